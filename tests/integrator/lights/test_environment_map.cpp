// Equirectangular environment: Cycles' mapping convention, chi-square goodness of fit of the
// importance sampler against its own pdf, solid-angle consistency, and irradiance against a
// quadrature of environment().
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "light_test_util.h"
#include "render/environment_map.h"
#include "render/light_sampler.h"

namespace gdpt {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// A w x h image: smooth positive background plus a few bright spots (a "sun" among them).
ImageDesc test_image(int w, int h, uint32_t seed) {
  ImageDesc img;
  img.name = "env";
  img.width = w;
  img.height = h;
  img.rgba.assign(size_t(w) * h * 4, 1.0f);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> U(0.05f, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = &img.rgba[(size_t(y) * w + x) * 4];
      p[0] = U(rng);
      p[1] = 0.5f * U(rng);
      p[2] = 0.2f + 0.1f * std::sin(float(x));
    }
  for (int k = 0; k < 3; ++k) {
    const int x = int(rng() % uint32_t(w)), y = int(rng() % uint32_t(h));
    float* p = &img.rgba[(size_t(y) * w + x) * 4];
    p[0] = p[1] = p[2] = 40.0f * float(k + 1);
  }
  return img;
}

TEST(EnvironmentMap, CyclesEquirectangularConvention) {
  // direction_to_equirectangular: u = 0.5 - atan2(y, x) / 2pi, v = 1 - acos(z) / pi.
  const Vec2f px = EnvironmentMap::direction_to_uv({1, 0, 0});
  EXPECT_NEAR(px.x, 0.5f, 1e-6f);
  EXPECT_NEAR(px.y, 0.5f, 1e-6f);
  EXPECT_NEAR(EnvironmentMap::direction_to_uv({0, 1, 0}).x, 0.25f, 1e-6f);
  EXPECT_NEAR(EnvironmentMap::direction_to_uv({0, -1, 0}).x, 0.75f, 1e-6f);
  EXPECT_NEAR(EnvironmentMap::direction_to_uv({0, 0, 1}).y, 1.0f, 1e-6f);
  EXPECT_NEAR(EnvironmentMap::direction_to_uv({0, 0, -1}).y, 0.0f, 1e-6f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> U(0.01f, 0.99f);
  for (int i = 0; i < 100; ++i) {
    const Vec2f uv(U(rng), U(rng));
    const Vec2f back = EnvironmentMap::direction_to_uv(EnvironmentMap::uv_to_direction(uv));
    EXPECT_NEAR(back.x, uv.x, 1e-5f);
    EXPECT_NEAR(back.y, uv.y, 1e-5f);
  }
}

TEST(EnvironmentMap, LookupOrientationAndRotation) {
  // 4 x 2 image, only the pixel at column 2 (u in [0.5, 0.75)), top row is bright: the
  // direction just below +Z towards -Y... take its centre uv = (0.625, 0.75).
  ImageDesc img;
  img.width = 4;
  img.height = 2;
  img.rgba.assign(4 * 2 * 4, 0.0f);
  img.rgba[(1 * 4 + 2) * 4 + 0] = 8.0f;
  const Vec3f d = EnvironmentMap::uv_to_direction({0.625f, 0.75f});
  EXPECT_GT(d.z, 0.0f);  // top row = upper hemisphere
  EXPECT_LT(d.y, 0.0f);  // u in (0.5, 1) = -Y side
  const EnvironmentMap env(img, Transform(), 2.0f);
  EXPECT_NEAR(env.eval(d).x, 16.0f, 1e-4f);  // strength multiplies
  // World rotation: rotating lookups by 90 degrees about Z moves the bright texel.
  const float rows[12] = {0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0};  // (x,y) -> (-y, x)
  const Transform rot = Transform::from_rows(rows);
  const EnvironmentMap rotated(img, rot, 1.0f);
  const Vec3f world = rot.inverse().vector(d);
  EXPECT_NEAR(rotated.eval(world).x, 8.0f, 1e-4f);
  EXPECT_NEAR(rotated.pdf(world), env.pdf(d), 1e-4f * env.pdf(d));
  float pdf = 0;
  const Vec3f s = rotated.sample({0.4f, 0.6f}, &pdf);
  EXPECT_NEAR(rotated.pdf(s), pdf, 1e-3f * pdf);
}

TEST(EnvironmentMap, ChiSquareSampleAgainstPdf) {
  // Bins are unions of sampling cells or whole fractions of them, so the midpoint rule below
  // integrates the piecewise-constant (in u, v) density exactly.
  struct Case {
    int w, h, bu, bv;
  };
  for (const auto& [w, h, bu, bv] :
       {Case{8, 4, 32, 16}, Case{64, 32, 32, 16}, Case{37, 19, 37, 19}}) {
    Scene scene = test::black_scene();
    scene.images.push_back(test_image(w, h, uint32_t(w)));
    scene.world.image = 0;
    scene.world.strength = 1.0f;
    const LightSampler lights(scene, {}, {});
    ASSERT_TRUE(lights.has_environment());
    // Bins in the equirectangular (u, v) of the sampled direction.
    const size_t n = 400000;
    std::vector<double> observed(bu * bv, 0.0), expected(bu * bv, 0.0);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    for (size_t i = 0; i < n; ++i) {
      const LightSample s = lights.sample({0, 0, 0}, U(rng), {U(rng), U(rng)});
      ASSERT_TRUE(s.valid);
      const Vec2f uv = EnvironmentMap::direction_to_uv(s.direction);
      const int i_u = std::min(int(uv.x * bu), bu - 1), i_v = std::min(int(uv.y * bv), bv - 1);
      observed[size_t(i_v) * bu + i_u] += 1.0;
    }
    // Expected counts: integrate pdf_environment over each bin in solid angle (midpoint rule on
    // a fine sub-grid in (u, v); dOmega = 2 pi^2 sin(theta) du dv).
    const int sub = 12;
    double total = 0;
    for (int j = 0; j < bv; ++j)
      for (int i = 0; i < bu; ++i) {
        double integral = 0;
        for (int b = 0; b < sub; ++b)
          for (int a = 0; a < sub; ++a) {
            const Vec2f uv((i + (a + 0.5f) / sub) / bu, (j + (b + 0.5f) / sub) / bv);
            const Vec3f d = EnvironmentMap::uv_to_direction(uv);
            const double sin_theta = std::sqrt(double(d.x) * d.x + double(d.y) * d.y);
            integral += lights.pdf_environment(d) * 2.0 * kPiD * kPiD * sin_theta /
                        (double(bu) * bv * sub * sub);
          }
        expected[size_t(j) * bu + i] = integral * n;
        total += integral;
      }
    EXPECT_NEAR(total, 1.0, 2e-3) << w << "x" << h;
    // Pool bins with fewer than 5 expected samples, as Mitsuba's chi2 test does.
    double chi2 = 0, pooled_obs = 0, pooled_exp = 0;
    int dof = -1;
    for (size_t k = 0; k < observed.size(); ++k) {
      if (expected[k] < 5.0) {
        pooled_obs += observed[k];
        pooled_exp += expected[k];
        continue;
      }
      chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
      ++dof;
    }
    if (pooled_exp >= 5.0) {
      chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
      ++dof;
    }
    const double p = test::chi2_p_value(chi2, dof);
    EXPECT_GT(p, 0.01) << w << "x" << h << " chi2 " << chi2 << " dof " << dof;
  }
}

TEST(EnvironmentMap, SolidAngleAndIrradianceAgainstQuadrature) {
  Scene scene = test::black_scene();
  scene.images.push_back(test_image(48, 24, 11));
  scene.world.image = 0;
  scene.world.strength = 0.7f;
  const LightSampler lights(scene, {}, {});
  const Vec3f n = normalize(Vec3f(0.3f, -0.5f, 0.8f));
  const test::Estimate e = test::estimate(lights, {0, 0, 0}, n, 1000000);
  EXPECT_NEAR(e.solid_angle, 4.0 * kPiD, 2e-2 * 4.0 * kPiD);
  // Quadrature of environment(d) cos over the sphere in (u, v), 8 points per texel each way.
  const int qu = 48 * 8, qv = 24 * 8;
  double E = 0;
  for (int j = 0; j < qv; ++j)
    for (int i = 0; i < qu; ++i) {
      const Vec2f uv((i + 0.5f) / qu, (j + 0.5f) / qv);
      const Vec3f d = EnvironmentMap::uv_to_direction(uv);
      const double sin_theta = std::sqrt(double(d.x) * d.x + double(d.y) * d.y);
      E += lights.environment(d).x * std::max(0.0, double(dot(n, d))) * 2.0 * kPiD * kPiD *
           sin_theta / (double(qu) * qv);
    }
  EXPECT_NEAR(e.irradiance, E, 5e-3 * E);
}

TEST(EnvironmentMap, BlackImageIsNoLight) {
  Scene scene = test::black_scene();
  ImageDesc img;
  img.width = 4;
  img.height = 2;
  img.rgba.assign(32, 0.0f);
  scene.images.push_back(img);
  scene.world.image = 0;
  const LightSampler lights(scene, {}, {});
  EXPECT_TRUE(lights.empty());
  EXPECT_FALSE(lights.has_environment());
  EXPECT_EQ(lights.pdf_environment({0, 0, 1}), 0.0f);
  EXPECT_FALSE(lights.sample({0, 0, 0}, 0.5f, {0.5f, 0.5f}).valid);
}

}  // namespace
}  // namespace gdpt
