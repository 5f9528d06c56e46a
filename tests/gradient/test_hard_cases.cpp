// Numerical hard cases of the integrators (issue: correctness and stability on hard cases).
// Oracles: exact linearity in light power (same seed, same paths), invariance under a change of
// unit scale, the same scene without the degenerate geometry, exact darkness, and G-PT + L2
// converging to a converged PT image. Every pass of every render must be finite.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "reconstruct/reconstruct.h"
#include "testing/gradient_scenes.h"

namespace gdpt::gradient_test {
namespace {

using Mode = RenderSettings::Mode;
constexpr Mode kModes[] = {Mode::PT, Mode::GPT};

const char* mode_name(Mode m) {
  return m == Mode::PT ? "PT" : "G-PT";
}

bool all_finite(const Passes& p) {
  for (const auto* v : {&p.primal, &p.dx, &p.dy, &p.emission, &p.variance, &p.failures})
    for (float f : *v)
      if (!std::isfinite(f)) return false;
  return true;
}

double mean(const std::vector<float>& v) {
  double s = 0.0;
  for (float f : v) s += f;
  return s / double(v.size());
}

// relMSE of `a` against `ref` on k x k block means (the comparison of two noisy images of the same
// expectation is dominated by noise per pixel; block means see a bias on a region).
double block_rel_mse(const Passes& shape, const std::vector<float>& a,
                     const std::vector<float>& ref, int k) {
  const int bw = shape.w / k, bh = shape.h / k;
  std::vector<float> ma(size_t(bw * bh * 3)), mr(ma.size());
  for (int y = 0; y < bh * k; ++y)
    for (int x = 0; x < bw * k; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t i = size_t(y * shape.w + x) * 3 + size_t(c);
        const size_t b = size_t((y / k) * bw + x / k) * 3 + size_t(c);
        ma[b] += a[i] / float(k * k);
        mr[b] += ref[i] / float(k * k);
      }
  return rel_mse(ma, mr);
}

// Every length of the scene times k (instances, camera, lights, clipping); light powers of
// point, spot and area lights times k^2 so that radiance is unchanged. Emission shaders and the
// world are radiances already.
Scene scaled(Scene s, float k) {
  for (Instance& i : s.instances)
    for (auto& row : i.object_to_world.m)
      for (float& v : row) v *= k;
  auto move = [k](Transform& t) {
    for (int r = 0; r < 3; ++r) t.m[r][3] *= k;
  };
  move(s.camera.camera_to_world);
  s.camera.clip_start *= k;
  s.camera.clip_end *= k;
  s.camera.focus_distance *= k;
  s.camera.aperture_radius *= k;
  for (Light& l : s.lights) {
    move(l.light_to_world);
    if (l.type == Light::Type::Sun) continue;
    l.power *= k * k;
    l.radius *= k;
    l.size_x *= k;
    l.size_y *= k;
  }
  return s;
}

// Same scene, same seed, every light k times brighter: the paths are the same, so every radiance
// pass scales by k exactly up to float rounding (no clamp is set).
TEST(HardCases, MegawattLightsScaleTheImageLinearly) {
  const double k = 1e5;  // 10 W -> 1 MW
  Scene dim = make_scene(SceneKind::MixedLights, 16);
  Scene bright = dim;
  for (Light& l : bright.lights) l.power *= float(k);
  bright.materials[4].nodes[0].strength = FloatInput(6.0f * float(k));
  for (const Mode m : kModes) {
    const Passes a = render(dim, settings(m, 64, 3)), b = render(bright, settings(m, 64, 3));
    ASSERT_TRUE(all_finite(b)) << mode_name(m);
    for (const auto pass : {&Passes::primal, &Passes::dx, &Passes::dy}) {
      double worst = 0.0, scale = 0.0;
      for (size_t i = 0; i < (a.*pass).size(); ++i) {
        worst = std::max(worst, std::fabs((b.*pass)[i] - k * (a.*pass)[i]));
        scale = std::max(scale, std::fabs(k * (a.*pass)[i]));
      }
      EXPECT_LT(worst, 1e-4 * scale) << mode_name(m);
    }
  }
}

// A scene modelled in 0.1 mm or in 10 km units renders the same image: ray offsets, shadow-ray
// ends, light-sample distances and clipping must be relative to the scene, not absolute. The
// scaled render (same seed) must be as close to the unit-scale one as a second seed is.
TEST(HardCases, UnitScaleDoesNotChangeTheImage) {
  const Scene base = make_scene(SceneKind::MixedLights, 24);
  for (const Mode m : kModes) {
    const Passes ref = render(base, settings(m, 256, 21));
    const Passes other = render(base, settings(m, 256, 22));
    const double noise = block_rel_mse(ref, other.primal, ref.primal, 4);
    for (const float k : {1e-4f, 1e4f}) {
      const Passes p = render(scaled(base, k), settings(m, 256, 21));
      ASSERT_TRUE(all_finite(p)) << mode_name(m) << " scale " << k;
      const double err = block_rel_mse(ref, p.primal, ref.primal, 4);
      std::printf("[unit scale %g %s] block relMSE %.3e (another seed: %.3e), mean %.4f / %.4f\n",
                  double(k), mode_name(m), err, noise, mean(p.primal), mean(ref.primal));
      EXPECT_LT(err, 2.0 * noise + 1e-6) << mode_name(m) << " scale " << k;
    }
  }
}

// Zero-area triangles (repeated and collinear vertices), in an emissive mesh and a wall: no NaN,
// and the image is the scene's without them (same seed) within noise.
TEST(HardCases, DegenerateTrianglesChangeNothing) {
  Scene clean = make_scene(SceneKind::MixedLights, 24);
  Scene dirty = clean;
  for (Mesh& mesh : dirty.meshes) {
    const uint32_t n = uint32_t(mesh.positions.size());
    mesh.positions.push_back(mesh.positions[0] * 0.5f + mesh.positions[1] * 0.5f);  // collinear
    const std::vector<uint32_t> extra = {0, 0, 1, 2, 2, 2, 0, 1, n};
    mesh.indices.insert(mesh.indices.end(), extra.begin(), extra.end());
    if (!mesh.corner_normals.empty())
      for (size_t i = 0; i < extra.size(); ++i) mesh.corner_normals.push_back({0, 0, 1});
  }
  for (const Mode m : kModes) {
    const Passes a = render(clean, settings(m, 256, 5)), b = render(dirty, settings(m, 256, 5));
    const Passes c = render(clean, settings(m, 256, 6));
    ASSERT_TRUE(all_finite(b)) << mode_name(m);
    const double err = block_rel_mse(a, b.primal, a.primal, 4);
    const double noise = block_rel_mse(a, c.primal, a.primal, 4);
    std::printf("[degenerate %s] block relMSE %.3e (another seed: %.3e)\n", mode_name(m), err,
                noise);
    EXPECT_LT(err, 2.0 * noise + 1e-6) << mode_name(m);
  }
}

// Lights enclosed by closed, opaque geometry light nothing: every pass exactly black.
TEST(HardCases, LightsInsideClosedObjectsLightNothing) {
  Scene s = make_scene(SceneKind::MixedLights, 16);
  s.lights.resize(2);      // the point light and the sphere light
  s.instances.pop_back();  // the emissive quad
  s.meshes.push_back(sphere(0.25f, 16, 8));
  const uint32_t ball = uint32_t(s.meshes.size() - 1);
  for (const Light& l : s.lights) {
    const Vec3f c(l.light_to_world.m[0][3], l.light_to_world.m[1][3], l.light_to_world.m[2][3]);
    s.instances.push_back(place(ball, 0, transform(0, 0, c)));
  }
  for (const Mode m : kModes) {
    const Passes p = render(s, settings(m, 32, 1));
    ASSERT_TRUE(all_finite(p));
    for (const auto pass : {&Passes::primal, &Passes::dx, &Passes::dy, &Passes::emission})
      for (float v : p.*pass) ASSERT_EQ(v, 0.0f) << mode_name(m);
  }
}

// G-PT reconstructed with L2 against a converged PT image of the same scene, on block means.
void expect_l2_matches_pt(const char* name, const Scene& scene, int gpt_spp, int pt_spp,
                          double tolerance) {
  const Passes g = render(scene, settings(Mode::GPT, gpt_spp, 31));
  ASSERT_TRUE(all_finite(g)) << name;
  const Passes ref = render(scene, settings(Mode::PT, pt_spp, 32));
  ASSERT_TRUE(all_finite(ref)) << name;
  const std::vector<float> l2 = reconstruct_l2(g, true);
  std::vector<float> ref_total(ref.primal.size());
  for (size_t i = 0; i < ref_total.size(); ++i) ref_total[i] = ref.primal[i] + ref.emission[i];
  const double err = block_rel_mse(g, l2, ref_total, 4);
  std::vector<float> g_total(g.primal.size());
  for (size_t i = 0; i < g_total.size(); ++i) g_total[i] = g.primal[i] + g.emission[i];
  std::printf("[%s] G-PT+L2 vs PT block relMSE %.3e (G-PT primal %.3e); means %.4f %.4f %.4f\n",
              name, err, block_rel_mse(g, g_total, ref_total, 4), mean(l2), mean(g_total),
              mean(ref_total));
  EXPECT_LT(err, tolerance) << name;
}

// Shading normals pointing away from the geometric normal (inverted corner normals on the back
// wall): paths must stay finite and G-PT must still converge to PT, which keeps the normal as
// Cycles does. (A G-PT-only fallback to the flat normal lit the wall: relMSE 0.35; noise ~1e-5.)
TEST(HardCases, ShadingNormalsFacingAway) {
  Scene s = make_scene(SceneKind::CornellDiffuse, 24);
  Mesh wall = quad(1.0f);
  wall.corner_normals.assign(wall.indices.size(), Vec3f(0.3f, 0.0f, -1.0f) * (1.0f / 1.044f));
  s.meshes.push_back(wall);
  s.instances[2].mesh = uint32_t(s.meshes.size() - 1);  // the back wall
  expect_l2_matches_pt("inverted-normals", s, 256, 2048, 2e-4);
}

// An emissive panel seen directly at a grazing angle and through a smooth glass sphere, and
// nested dielectrics (a glass ball of ior 1.33 inside one of 1.5). The gradients here pass the
// per-pixel z-test of test_gradient_unbiased (max |z| 3.3 at 1024 spp); the L2 image's error is
// gradient noise through the glass (1e-3 to 2.9e-3 over three seed pairs at 512 spp).
TEST(HardCases, EmittersAtGrazingAnglesAndThroughGlass) {
  Scene s = make_scene(SceneKind::CornellGlass, 24, 0.0f);
  s.lights.clear();
  s.materials.push_back(emissive({1.0f, 0.9f, 0.8f}, 8.0f));  // 4
  s.meshes.push_back(quad(0.3f));
  const uint32_t panel = uint32_t(s.meshes.size() - 1);
  // Nearly edge-on to the camera, behind the glass sphere.
  s.instances.push_back(place(panel, 4, transform(-1.45f, 0.0f, {-0.3f, -0.3f, -0.7f})));
  s.instances.push_back(place(panel, 4, transform(kPi / 2, 0.0f, {0.0f, 0.97f, 0.0f})));
  s.materials.push_back(glass(0.0f, 1.33f));  // 5
  s.meshes.push_back(sphere(0.2f, 24, 12));
  s.instances.push_back(
      place(uint32_t(s.meshes.size() - 1), 5, transform(0, 0, {-0.3f, -0.55f, -0.1f})));
  expect_l2_matches_pt("grazing-and-glass", s, 1024, 4096, 4e-3);
}

// Reconstruction: any alpha from 1e-4 to 10 recovers exact data; with noisy gradients, a large
// alpha returns the primal and a small one stays finite and close to the gradients' image.
TEST(HardCases, ReconstructionAlphaRange) {
  const int w = 29, h = 23;
  std::vector<float> truth(size_t(w * h * 3));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        truth[size_t(y * w + x) * 3 + size_t(c)] =
            0.5f + 0.4f * std::sin(0.3f * float(x) + float(c)) * std::cos(0.2f * float(y));
  std::vector<float> gx(truth.size(), 0.0f), gy(truth.size(), 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t i = size_t(y * w + x) * 3 + size_t(c);
        if (x + 1 < w) gx[i] = truth[i + 3] - truth[i];
        if (y + 1 < h) gy[i] = truth[i + size_t(w) * 3] - truth[i];
      }
  for (const float alpha : {1e-4f, 1e-2f, 0.2f, 1.0f, 10.0f})
    for (const auto norm : {ReconstructionNorm::L2, ReconstructionNorm::L1}) {
      ReconstructionSettings rs;
      rs.norm = norm;
      rs.alpha = alpha;
      const auto out =
          reconstruct({w, h, truth.data(), gx.data(), gy.data(), nullptr, nullptr}, rs);
      double worst = 0.0;
      for (size_t i = 0; i < out.size(); ++i)
        worst = std::max(worst, std::fabs(double(out[i]) - truth[i]));
      EXPECT_LT(worst, 1e-3) << "alpha " << alpha;
    }
  // A primal off by a constant 0.1 with exact gradients: the solution keeps the gradients and
  // moves towards the primal's mean; the mean offset is 0.1 for every alpha (it is the only
  // way to match the primal's mean), while the shape is the truth's.
  std::vector<float> shifted(truth);
  for (float& v : shifted) v += 0.1f;
  for (const float alpha : {1e-4f, 10.0f}) {
    ReconstructionSettings rs;
    rs.norm = ReconstructionNorm::L2;
    rs.alpha = alpha;
    const auto out =
        reconstruct({w, h, shifted.data(), gx.data(), gy.data(), nullptr, nullptr}, rs);
    double worst = 0.0;
    for (size_t i = 0; i < out.size(); ++i)
      worst = std::max(worst, std::fabs(double(out[i]) - shifted[i]));
    EXPECT_LT(worst, 1e-3) << "alpha " << alpha;
  }
}

}  // namespace
}  // namespace gdpt::gradient_test
