// Multiscatter GGX glass (Closure::multiscatter in bsdf_ggx_dielectric.h, ggx_dielectric_albedo.h):
// a white, non-absorbing rough dielectric reflects and refracts all the light from either side,
// which plain GGX glass fails; the table agrees with the single-scattering lobe's sampled albedo;
// light leaves through tilted microfacets past the shading normal's critical angle; the Glass and
// Principled nodes switch it on as Cycles does. Sampling against the density is in test_bsdf_chi2
// (MultiscatterGlass*).
#include <gtest/gtest.h>

#include "shaders/ggx_dielectric_albedo.h"
#include "shaders/material.h"
#include "testing/chi2.h"
#include "tests/shaders/lobe_factory.h"

namespace gdpt::test {
namespace {

double albedo(const ClosureSet& set, Vec3f wi, int samples = 400000) {
  return sampled_albedo(set, wi, samples, 91);
}

const float kRoughness[] = {0.3f, 0.6f, 1.0f};
// Entering (cos_i > 0) and leaving (cos_i < 0, total internal reflection beyond 0.75).
const float kIncidentCos[] = {1.0f, 0.7f, 0.4f, 0.15f, -0.9f, -0.5f};

TEST(GgxMultiscatterGlass, WhiteFurnaceScattersAllLight) {
  for (float ior : {1.5f, 1.33f})
    for (float r : kRoughness)
      for (float mu : kIncidentCos) {
        const double e = albedo(set_of({multiscatter_glass(glass(r * r, ior))}), incident(mu));
        EXPECT_NEAR(e, 1.0, 0.02) << "ior " << ior << " roughness " << r << " cos_i " << mu;
      }
}

// What the compensation is for: plain GGX glass loses more light than the furnace's tolerance at
// roughness 1 from every angle, at 0.6 from all but normal incidence (a quarter from inside), at
// 0.3 at grazing incidence.
TEST(GgxMultiscatterGlass, PlainGgxGlassFailsTheFurnace) {
  for (float r : {0.6f, 1.0f})
    for (float mu : kIncidentCos) {
      if (r < 1.0f && mu == 1.0f) continue;
      const double e = albedo(set_of({glass(r * r, 1.5f)}), incident(mu));
      EXPECT_LT(e, 0.98) << "roughness " << r << " cos_i " << mu;
      EXPECT_GT(e, 0.3) << "roughness " << r << " cos_i " << mu;
    }
  EXPECT_LT(albedo(set_of({glass(0.09f, 1.5f)}), incident(0.15f)), 0.96);
}

// The table is the single-scattering lobe's albedo (the lobe with a black multiscatter_tint:
// no compensation), between its nodes too (IORs off the eta grid, both sides).
TEST(GgxMultiscatterGlass, TableMatchesTheSingleScatteringAlbedo) {
  for (float ior : {1.45f, 2.2f})
    for (float r : {0.2f, 0.45f, 0.8f})
      for (float mu : kIncidentCos) {
        const float eta = mu > 0.0f ? ior : 1.0f / ior;
        const Closure bare = multiscatter_glass(glass(r * r, ior), Spectrum(0.0f));
        const double single = albedo(set_of({bare}), incident(mu), 200000);
        EXPECT_NEAR(ggx_dielectric_albedo(std::fabs(mu), r * r, eta), single, 0.012)
            << "ior " << ior << " roughness " << r << " cos_i " << mu;
      }
}

// The added light is tinted by multiscatter_tint; the shape is the single-scattering lobe's.
TEST(GgxMultiscatterGlass, CompensationScalesTheSingleScatteringLobe) {
  const Spectrum tint(1.0f, 0.5f, 0.0f);
  const Closure plain = multiscatter_glass(glass(0.36f, 1.5f), Spectrum(0.0f));
  const Closure ms = multiscatter_glass(glass(0.36f, 1.5f), tint);
  const Vec3f wi = incident(0.6f);
  const float e = ggx_dielectric_albedo(0.6f, 0.36f, 1.5f);
  for (const Vec3f wo : {Vec3f(0.3f, -0.2f, 0.9f), Vec3f(-0.4f, -0.1f, -0.8f)}) {
    const Spectrum p = set_of({plain}).eval(wi, normalize(wo));
    const Spectrum m = set_of({ms}).eval(wi, normalize(wo));
    ASSERT_GT(p.x, 0.0f);
    EXPECT_NEAR(m.x / p.x, 1.0f / e, 1e-4f);
    EXPECT_NEAR(m.y / p.y, 1.0f + 0.5f * (1.0f / e - 1.0f), 1e-4f);
    EXPECT_NEAR(m.z / p.z, 1.0f, 1e-6f);
    EXPECT_EQ(set_of({plain}).pdf(wi, normalize(wo)), set_of({ms}).pdf(wi, normalize(wo)));
  }
}

// Inside glass beyond the critical angle (cos_i 0.5 < 0.745 at ior 1.5) the shading normal
// reflects everything, but microfacets tilted towards wi refract, as in Cycles' random walk.
TEST(GgxMultiscatterGlass, RefractsPastTheCriticalAngle) {
  const Vec3f wi = incident(-0.5f);
  const Vec3f wo = normalize(Vec3f(-0.9f, -0.28f, 0.3f));
  EXPECT_EQ(set_of({glass(0.36f, 1.5f)}).eval(wi, wo).x, 0.0f);
  EXPECT_GT(set_of({multiscatter_glass(glass(0.36f, 1.5f))}).eval(wi, wo).x, 0.01f);
}

TEST(GgxMultiscatterGlass, GlassNodeCompensates) {
  ShaderNode n;
  n.kind = ShaderNodeKind::Glass;
  n.color = ColorInput(Spectrum(1.0f, 0.8f, 0.6f));
  n.roughness = FloatInput(0.6f);
  n.ior = FloatInput(1.45f);
  n.distribution = MicrofacetDistribution::MultiscatterGGX;
  for (bool front : {true, false}) {
    const ClosureSet s = one_node_closures(n, front);
    ASSERT_EQ(s.count(), 1);
    EXPECT_EQ(s[0].type, ClosureType::GGXDielectric);
    EXPECT_EQ(s[0].distribution, MicrofacetDistribution::GGX);
    EXPECT_TRUE(s[0].multiscatter);
    EXPECT_FLOAT_EQ(s[0].multiscatter_tint.z, 0.6f);
  }
  n.color = ColorInput(Spectrum(1.0f));
  for (bool front : {true, false})
    for (float mu : kIncidentCos)
      EXPECT_NEAR(albedo(one_node_closures(n, front), incident(mu)), 1.0, 0.02)
          << "front " << front << " cos_i " << mu;
  n.distribution = MicrofacetDistribution::GGX;
  EXPECT_FALSE(one_node_closures(n)[0].multiscatter);
}

// Principled, transmission 1, white: its glass alone, compensated above roughness 0.05 (where
// Cycles switches to its multiple-scattering glass), and then white-furnace conserving.
TEST(GgxMultiscatterGlass, PrincipledTransmissionCompensates) {
  ShaderNode n;
  n.kind = ShaderNodeKind::Principled;
  n.color = ColorInput(Spectrum(1.0f));
  n.transmission = FloatInput(1.0f);
  n.ior = FloatInput(1.45f);
  n.distribution = MicrofacetDistribution::MultiscatterGGX;
  n.roughness = FloatInput(0.04f);
  ClosureSet s = one_node_closures(n);
  ASSERT_EQ(s.count(), 1);
  EXPECT_FALSE(s[0].multiscatter);
  for (float r : kRoughness) {
    n.roughness = FloatInput(r);
    s = one_node_closures(n);
    ASSERT_EQ(s.count(), 1);
    EXPECT_EQ(s[0].type, ClosureType::GGXDielectric);
    EXPECT_TRUE(s[0].multiscatter);
    for (float mu : kIncidentCos)
      EXPECT_NEAR(albedo(s, incident(mu)), 1.0, 0.02) << "roughness " << r << " cos_i " << mu;
  }
}

}  // namespace
}  // namespace gdpt::test
