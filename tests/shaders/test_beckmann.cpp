// The Beckmann distribution (shaders/beckmann.h) and its lobes against independent oracles:
// D's normalisation by quadrature, the visible-normal density integrating to 1 (so the sampler's
// pdf carries the exact Smith G1), Cycles 3.4's formulas for D, the G1 fit and the reflection and
// refraction values (written out here from the Walter et al. 2007 equations Cycles follows), the
// fit against the exact term, and the white furnace; the same of the anisotropic distribution
// (Cycles 3.4's anisotropic D and bsdf_beckmann_aniso_G1). Sampling against pdf: test_bsdf_chi2.
#include <gtest/gtest.h>

#include "shaders/beckmann.h"
#include "shaders/fresnel.h"
#include "testing/chi2.h"
#include "tests/shaders/lobe_factory.h"

namespace gdpt::test {
namespace {

const float kAlphas[] = {0.01f, 0.05f, 0.2f, 0.5f, 1.0f};

// Cycles 3.4's isotropic Beckmann D and G1 (bsdf_microfacet.h), in double, from the cosines.
double cycles_d(double cos_m, double alpha) {
  const double c2 = cos_m * cos_m, a2 = alpha * alpha;
  return std::exp(-(1.0 - c2) / c2 / a2) / (M_PI * a2 * c2 * c2);
}
double cycles_g1(double cos_n, double alpha) {
  const double c2 = cos_n * cos_n;
  const double inv_a = alpha * std::sqrt((1.0 - c2) / c2);
  if (inv_a < 0.625) return 1.0;
  const double a = 1.0 / inv_a;
  return (2.181 * a + 3.535) * a / ((2.577 * a + 2.276) * a + 1.0);
}

// The cosine of m to the normal in double: float directions are unit to ~1e-7 only, which the
// exponent of a narrow D amplifies.
double unit_cos(Vec3f m) {
  return m.z / std::sqrt(double(m.x) * m.x + double(m.y) * m.y + double(m.z) * m.z);
}

TEST(Beckmann, DistributionIntegratesToOneOverProjectedArea) {
  for (float a : kAlphas) {
    const Beckmann b(a);
    const double mass = hemisphere_integral([&](Vec3f m) { return double(b.D(m)) * m.z; });
    EXPECT_NEAR(mass, 1.0, 1e-4) << "alpha " << a;
  }
}

// The visible normals' density integrates to 1 for every view: smith_G1 is the exact Smith term
// (cos_i / the projected area of the visible microfacets), as the sampler's pdf needs.
TEST(Beckmann, VisibleNormalDensityIntegratesToOne) {
  for (float a : kAlphas)
    for (float c : {1.0f, 0.8f, 0.4f, 0.1f, 0.01f}) {
      const Beckmann b(a);
      const Vec3f wi = incident(c);
      const double mass =
          hemisphere_integral([&](Vec3f m) { return double(b.pdf_visible(wi, m)); });
      EXPECT_NEAR(mass, 1.0, 2e-4) << "alpha " << a << " cos_i " << c;
    }
}

TEST(Beckmann, DAndG1AreCyclesFormulas) {
  Pcg32 rng(11);
  for (float a : kAlphas)
    for (int i = 0; i < 200; ++i) {
      const Beckmann b(a);
      const Vec3f m = direction(0.2 + 0.8 * rng.uniform(), 2 * M_PI * rng.uniform());
      const double d = cycles_d(unit_cos(m), a);
      if (d > 1e-30) {
        EXPECT_NEAR(b.D(m), d, 2e-4 * d) << "alpha " << a << " cos " << m.z;
      }
      const Vec3f w = direction(0.005 + 0.995 * rng.uniform(), 2 * M_PI * rng.uniform());
      EXPECT_NEAR(b.G1(w), cycles_g1(unit_cos(w), a), 2e-5) << "alpha " << a << " cos " << w.z;
      EXPECT_EQ(b.G1(w), b.G1(-w));
    }
}

// Cycles' rational fit stays within 0.5% of the exact Smith term it approximates (and reaches 0
// at grazing incidence, 1 near the normal, with it).
TEST(Beckmann, G1FitIsCloseToTheExactSmithTerm) {
  for (float a : kAlphas)
    for (double c = 0.001; c <= 1.0; c += 0.001) {
      const Beckmann b(a);
      const Vec3f w = direction(c, 0.7);
      EXPECT_NEAR(b.G1(w), b.smith_G1(w), 5e-3 * b.smith_G1(w) + 1e-6)
          << "alpha " << a << " cos " << c;
    }
  EXPECT_EQ(Beckmann(0.5f).G1(Vec3f(1, 0, 0)), 0.0f);
  EXPECT_EQ(Beckmann(0.5f).smith_G1(Vec3f(1, 0, 0)), 0.0f);
  EXPECT_EQ(Beckmann(0.5f).smith_G1(Vec3f(0, 0, 1)), 1.0f);
}

// Sampled Glossy / Glass / Refraction lobes take Cycles 3.4's values: reflection
// D G1(cos_i) G1(cos_o) / (4 cos_i), refraction D G1 G1 eta^2 |i.h| |o.h| / (cos_i |i + eta o|^2),
// the Glass splitting them by the Fresnel term at the shading normal.
TEST(Beckmann, LobeValuesAreCyclesFormulas) {
  const float ior = 1.5f;
  const Closure lobes[] = {beckmann(ggx(0.3f)), beckmann(glass(0.2f, ior)),
                           beckmann(refraction(0.5f, ior))};
  Pcg32 rng(5);
  for (const Closure& lobe : lobes) {
    const ClosureSet set = set_of({lobe});
    int checked = 0;
    for (int i = 0; i < 2000; ++i) {
      const float side = i % 2 ? 1.0f : -1.0f;  // entering or leaving
      Vec3f wi = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
      wi.z *= side;
      const BsdfSample s = set.sample(wi, rng.uniform(), Vec2f(rng.uniform(), rng.uniform()));
      if (!s.valid) continue;
      // Cycles' frame: the normal towards wi, eta the IOR of the far side relative to wi's.
      const double ci = std::fabs(wi.z), co = std::fabs(s.wo.z);
      const double eta = side > 0 ? ior : 1.0 / ior;
      const double g = cycles_g1(ci, lobe.alpha) * cycles_g1(co, lobe.alpha);
      double expected;
      if (wi.z * s.wo.z > 0.0f) {
        const Vec3f h = normalize(wi + s.wo);
        expected = cycles_d(std::fabs(unit_cos(h)), lobe.alpha) * g / (4.0 * ci);
        if (lobe.fresnel == FresnelMode::Dielectric) expected *= fresnel_dielectric(ci, eta);
      } else {
        const Vec3f ht = wi + s.wo * float(eta);
        const Vec3f h = normalize(ht);
        expected = cycles_d(std::fabs(unit_cos(h)), lobe.alpha) * g * eta * eta *
                   std::fabs(dot(wi, h) * dot(s.wo, h)) / (ci * length_squared(ht));
        if (lobe.fresnel == FresnelMode::Dielectric) expected *= 1.0 - fresnel_dielectric(ci, eta);
      }
      EXPECT_NEAR(s.value.y, expected, 1e-3 * expected + 1e-7) << int(lobe.fresnel) << " " << i;
      ++checked;
    }
    EXPECT_GT(checked, 1000);
  }
}

// Cycles 3.4's anisotropic Beckmann D and G1 (bsdf_microfacet.h), in double: D from the slopes,
// G1 from the width along w's azimuth, (ax^2 cos^2 phi + ay^2 sin^2 phi).
double cycles_aniso_d(Vec3f m, double ax, double ay) {
  const double len = std::sqrt(double(m.x) * m.x + double(m.y) * m.y + double(m.z) * m.z);
  const double x = m.x / len, y = m.y / len, z = m.z / len;
  const double sx = -x / (z * ax), sy = -y / (z * ay);
  return std::exp(-sx * sx - sy * sy) / (M_PI * ax * ay * z * z * z * z);
}
double cycles_aniso_g1(Vec3f w, double ax, double ay) {
  const double len = std::sqrt(double(w.x) * w.x + double(w.y) * w.y + double(w.z) * w.z);
  const double x = w.x / len, y = w.y / len, c2 = double(w.z) * w.z / (len * len);
  const double alpha2 = (x * x * ax * ax + y * y * ay * ay) / (x * x + y * y);
  const double inv_a = std::sqrt(alpha2 * (1.0 - c2) / c2);
  if (inv_a < 0.625) return 1.0;
  const double a = 1.0 / inv_a;
  return (2.181 * a + 3.535) * a / ((2.577 * a + 2.276) * a + 1.0);
}

const float kWidths[][2] = {{0.05f, 0.4f}, {0.4f, 0.05f}, {0.2f, 0.6f}, {1.0f, 0.3f}};

TEST(Beckmann, AnisotropicDistributionIntegratesToOne) {
  for (const auto& w : kWidths) {
    const Beckmann b(w[0], w[1]);
    const double mass = hemisphere_integral([&](Vec3f m) { return double(b.D(m)) * m.z; });
    EXPECT_NEAR(mass, 1.0, 1e-4) << w[0] << " x " << w[1];
    for (float c : {1.0f, 0.7f, 0.3f, 0.05f})
      for (float phi : {0.0f, 0.8f, 2.0f}) {
        const Vec3f wi = direction(c, phi);
        const double visible =
            hemisphere_integral([&](Vec3f m) { return double(b.pdf_visible(wi, m)); });
        EXPECT_NEAR(visible, 1.0, 2e-4) << w[0] << " x " << w[1] << " cos " << c << " " << phi;
      }
  }
}

TEST(Beckmann, AnisotropicDAndG1AreCyclesFormulas) {
  Pcg32 rng(17);
  for (const auto& w : kWidths)
    for (int i = 0; i < 300; ++i) {
      const Beckmann b(w[0], w[1]);
      const Vec3f m = direction(0.2 + 0.8 * rng.uniform(), 2 * M_PI * rng.uniform());
      const double d = cycles_aniso_d(m, w[0], w[1]);
      if (d > 1e-30) {
        EXPECT_NEAR(b.D(m), d, 2e-4 * d) << w[0] << " x " << w[1];
      }
      const Vec3f v = direction(0.005 + 0.995 * rng.uniform(), 2 * M_PI * rng.uniform());
      EXPECT_NEAR(b.G1(v), cycles_aniso_g1(v, w[0], w[1]), 2e-5) << w[0] << " x " << w[1];
      // The fit stays close to the exact term here as well.
      EXPECT_NEAR(b.G1(v), b.smith_G1(v), 5e-3 * b.smith_G1(v) + 1e-6);
    }
  // Equal widths: the isotropic distribution.
  const Vec3f m = direction(0.6, 1.1);
  EXPECT_NEAR(Beckmann(0.3f, 0.3f).D(m), Beckmann(0.3f).D(m), 1e-5f * Beckmann(0.3f).D(m));
}

// The Anisotropic BSDF's lobe with Beckmann takes Cycles' value D G1(wi) G1(wo) / (4 cos_i) in
// the lobe's rotated frame, and differs from the anisotropic GGX lobe of the same widths.
TEST(Beckmann, AnisotropicLobeValuesAreCyclesFormulas) {
  const float ax = 0.08f, ay = 0.35f, turns = 0.15f;
  const Closure lobe = beckmann(aniso_ggx(ax, ay, 2.0f * float(M_PI) * turns));
  const ClosureSet set = set_of({lobe}),
                   as_ggx = set_of({aniso_ggx(ax, ay, 2.0f * float(M_PI) * turns)});
  // Cycles' tangent frame: the lobe's tangent (rotation) on x.
  const double cr = lobe.rotation.x, sr = lobe.rotation.y;
  auto to_lobe = [&](Vec3f v) {
    return Vec3f(float(cr * v.x + sr * v.y), float(cr * v.y - sr * v.x), v.z);
  };
  Pcg32 rng(23);
  int checked = 0;
  double differ = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3f wi = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
    const BsdfSample s = set.sample(wi, rng.uniform(), Vec2f(rng.uniform(), rng.uniform()));
    if (!s.valid) continue;
    const Vec3f h = normalize(wi + s.wo);
    const double expected = cycles_aniso_d(to_lobe(h), ax, ay) *
                            cycles_aniso_g1(to_lobe(wi), ax, ay) *
                            cycles_aniso_g1(to_lobe(s.wo), ax, ay) / (4.0 * wi.z);
    EXPECT_NEAR(s.value.y, expected, 1e-3 * expected + 1e-7) << i;
    differ = std::max(differ, std::fabs(as_ggx.eval(wi, s.wo).y - expected) / expected);
    ++checked;
  }
  EXPECT_GT(checked, 1500);
  EXPECT_GT(differ, 0.5);
}

TEST(Beckmann, WhiteFurnaceLossIsSmallForSmoothAndLargerForRough) {
  // Single scattering, as Cycles' Beckmann: energy is lost with roughness.
  const Vec3f wi = incident(0.8f);
  const ClosureSet smooth = set_of({beckmann(ggx(0.05f))}), rough = set_of({beckmann(ggx(1.0f))});
  const double e_smooth =
      hemisphere_integral([&](Vec3f wo) { return double(smooth.eval(wi, wo).y); });
  const double e_rough =
      hemisphere_integral([&](Vec3f wo) { return double(rough.eval(wi, wo).y); });
  EXPECT_NEAR(e_smooth, 1.0, 0.01);
  EXPECT_LT(e_rough, e_smooth - 0.2);
  EXPECT_GT(e_rough, 0.3);
}

}  // namespace
}  // namespace gdpt::test
