// The Ashikhmin-Shirley lobe (shaders/ashikhmin_shirley.h) against independent oracles: its
// half-vector density integrating to 1 by quadrature, Cycles 3.4's value and density
// (bsdf_ashikhmin_shirley_eval, written out here in double in Cycles' world-frame form: tangent
// basis from the rotated tangent, exponents 2 / alpha^2 - 2) at sampled and random pairs, and the
// sample weight cos_o / max(cos_i, cos_o). Sampling against pdf: test_bsdf_chi2; reciprocity and
// energy: test_bsdf_properties.
#include <gtest/gtest.h>

#include "shaders/ashikhmin_shirley.h"
#include "testing/chi2.h"
#include "tests/shaders/lobe_factory.h"

namespace gdpt::test {
namespace {

struct D3 {
  double x, y, z;
};
double dot3(D3 a, D3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
D3 unit(D3 a) {
  const double l = std::sqrt(dot3(a, a));
  return {a.x / l, a.y / l, a.z / l};
}

// Cycles 3.4's eval for N = +z and the lobe's tangent T = (cos angle, sin angle, 0), both
// directions above: f |cos_o| and the density.
double cycles_eval(double ax, double ay, double angle, D3 wi, D3 wo, double& pdf) {
  ax = std::clamp(ax, 1e-4, 1.0);
  ay = std::clamp(ay, 1e-4, 1.0);
  const double ni = std::max(wi.z, 1e-6), no = std::max(wo.z, 1e-6);
  const D3 h = unit({wi.x + wo.x, wi.y + wo.y, wi.z + wo.z});
  const double hi = std::max(std::fabs(dot3(h, wi)), 1e-6), hn = std::max(h.z, 1e-6);
  const double pump = 1.0 / std::max(1e-6, hi * std::max(ni, no));
  const double nx = 2.0 / (ax * ax) - 2.0, ny = 2.0 / (ay * ay) - 2.0;
  double lobe;
  if (nx == ny) {
    lobe = std::pow(hn, nx);
  } else {
    // make_orthonormals_tangent: Y = N x T, X = Y x N.
    const D3 x = {std::cos(angle), std::sin(angle), 0.0},
             y = {-std::sin(angle), std::cos(angle), 0};
    const double hx = dot3(h, x), hy = dot3(h, y);
    lobe = hn < 1.0 ? std::pow(hn, (nx * hx * hx + ny * hy * hy) / (1.0 - hn * hn)) : 1.0;
  }
  const double norm = std::sqrt((nx + 1.0) * (ny + 1.0)) / (8.0 * M_PI);
  pdf = norm * lobe / hi;
  return no * norm * lobe * pump;
}

TEST(AshikhminShirley, ExponentsAreCyclesRoughnessMapping) {
  EXPECT_FLOAT_EQ(AshikhminShirley::exponent(0.5f), 6.0f);
  EXPECT_FLOAT_EQ(AshikhminShirley::exponent(1.0f), 0.0f);
  EXPECT_FLOAT_EQ(AshikhminShirley::exponent(2.0f), 0.0f);      // clamped to 1
  EXPECT_FLOAT_EQ(AshikhminShirley::exponent(0.0f), 2e8f - 2);  // clamped to 1e-4
}

// p_h = 4 norm lobe integrates to 1 over the hemisphere of half vectors: the density of the
// normals sample_normal draws, isotropic and anisotropic.
TEST(AshikhminShirley, HalfVectorDensityIntegratesToOne) {
  const std::pair<float, float> widths[] = {{0.05f, 0.05f}, {0.3f, 0.3f}, {1.0f, 1.0f},
                                            {0.05f, 0.4f},  {0.5f, 0.1f}, {1.0f, 0.2f}};
  for (auto [ax, ay] : widths) {
    const AshikhminShirley as(ax, ay);
    const double mass =
        hemisphere_integral([&](Vec3f h) { return 4.0 * as.norm() * double(as.lobe(h)); });
    EXPECT_NEAR(mass, 1.0, 2e-4) << ax << " x " << ay;
  }
}

// Sampled and random pairs on both sides take Cycles' value and density; the sample weight is
// cos_o / max(cos_i, cos_o).
TEST(AshikhminShirley, ValuesAndDensitiesAreCyclesFormulas) {
  struct Lobe {
    float ax, ay, angle;
  };
  const Lobe lobes[] = {{0.3f, 0.3f, 0.0f},
                        {0.05f, 0.05f, 0.0f},
                        {1.0f, 1.0f, 0.0f},
                        {0.05f, 0.4f, 0.3f},
                        {0.5f, 0.1f, 2.0f}};
  Pcg32 rng(7);
  for (const Lobe& l : lobes) {
    const Closure c = ashikhmin_shirley(l.ax == l.ay ? ggx(l.ax) : aniso_ggx(l.ax, l.ay, l.angle));
    const ClosureSet set = set_of({c});
    int checked = 0;
    for (int i = 0; i < 2000; ++i) {
      const float side = i % 2 ? 1.0f : -1.0f;
      Vec3f wi = direction(0.02 + 0.98 * rng.uniform(), 2 * M_PI * rng.uniform());
      wi.z *= side;
      Vec3f wo = direction(0.02 + 0.98 * rng.uniform(), 2 * M_PI * rng.uniform());
      wo.z *= side;
      const BsdfSample s = set.sample(wi, rng.uniform(), Vec2f(rng.uniform(), rng.uniform()));
      if (s.valid && i % 4 < 2) {
        wo = s.wo;
        const double weight = std::fabs(wo.z) / std::max(std::fabs(wi.z), std::fabs(wo.z));
        EXPECT_NEAR(s.weight().y, weight, 2e-4 * weight + 1e-6);
      }
      // Cycles' frame: the normal towards wi.
      const D3 a = {wi.x, wi.y, wi.z * side}, b = {wo.x, wo.y, wo.z * side};
      double pdf;
      const double v = cycles_eval(l.ax, l.ay, l.angle, a, b, pdf);
      EXPECT_NEAR(set.eval(wi, wo).y, v, 2e-3 * v + 1e-7) << l.ax << "x" << l.ay << " " << i;
      EXPECT_NEAR(set.pdf(wi, wo), pdf, 2e-3 * pdf + 1e-7) << l.ax << "x" << l.ay << " " << i;
      checked += v > 1e-3;
    }
    EXPECT_GT(checked, 500) << l.ax << "x" << l.ay;
  }
}

// Roughness 1 (exponent 0): half vectors uniform over the hemisphere, f cos_o =
// cos_o / (8 pi |h.wi| max(cos_i, cos_o)).
TEST(AshikhminShirley, RoughnessOneIsUniformHalfVectors) {
  const ClosureSet set = set_of({ashikhmin_shirley(ggx(1.0f))});
  const Vec3f wi = normalize(Vec3f(0.3f, -0.2f, 0.8f)), wo = normalize(Vec3f(-0.5f, 0.1f, 0.4f));
  const Vec3f h = normalize(wi + wo);
  const float expected = wo.z / (8.0f * kPi * dot(h, wi) * std::max(wi.z, wo.z));
  EXPECT_NEAR(set.eval(wi, wo).y, expected, 1e-6f);
  EXPECT_NEAR(set.pdf(wi, wo), 1.0f / (8.0f * kPi * dot(h, wi)), 1e-6f);
}

}  // namespace
}  // namespace gdpt::test
