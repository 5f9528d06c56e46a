// Multiscatter GGX reflection (bsdf_ggx_multiscatter.h, ggx_albedo.h): a white lobe with its
// multiple-scattering lobe passes the white furnace, which plain GGX fails at high roughness.
// Sampling against the density is in test_bsdf_chi2 (MultiscatterLobe*, MultiscatterGGX*).
#include <gtest/gtest.h>

#include "shaders/material.h"
#include "testing/chi2.h"
#include "tests/shaders/lobe_factory.h"

namespace gdpt::test {
namespace {

double albedo(const ClosureSet& set, Vec3f wi, int samples = 400000) {
  return sampled_albedo(set, wi, samples, 77);
}

const float kRoughness[] = {0.3f, 0.6f, 1.0f};
const float kIncidentCos[] = {1.0f, 0.7f, 0.4f, 0.15f, -0.5f};

TEST(GgxMultiscatter, WhiteFurnaceReflectsAllLight) {
  for (float r : kRoughness)
    for (float mu : kIncidentCos) {
      const Closure g = ggx(r * r);
      const double e = albedo(set_of({g, multiscatter_of(g)}), incident(mu));
      EXPECT_NEAR(e, 1.0, 0.02) << "roughness " << r << " cos_i " << mu;
    }
}

// What the compensation is for: plain GGX loses light at roughness 1 from every angle (about
// two thirds at normal incidence).
TEST(GgxMultiscatter, PlainGgxFailsTheFurnaceAtRoughnessOne) {
  for (float mu : kIncidentCos) {
    const double e = albedo(set_of({ggx(1.0f)}), incident(mu));
    EXPECT_LT(e, 0.95) << "cos_i " << mu;
    EXPECT_GT(e, 0.2) << "cos_i " << mu;
  }
}

// The multiple-scattering lobe alone reflects what the tabulated single-scattering lobe lacks:
// 1 - E(cos_i), so the table agrees with the lobe's albedo.
TEST(GgxMultiscatter, TableMatchesTheSingleScatteringAlbedo) {
  for (float r : kRoughness)
    for (float mu : kIncidentCos) {
      const Closure g = ggx(r * r);
      const double single = albedo(set_of({g}), incident(mu));
      EXPECT_NEAR(ggx_albedo(std::fabs(mu), r * r), single, 0.01)
          << "roughness " << r << " cos_i " << mu;
      const double multiple = albedo(set_of({multiscatter_of(g)}), incident(mu));
      EXPECT_NEAR(multiple, 1.0 - single, 0.01) << "roughness " << r << " cos_i " << mu;
    }
}

// Kulla-Conty's colour: white stays white, a colour c < 1 scatters c^2 E_avg / (1 - c (1 -
// E_avg)) of the compensated light, less than c, and nothing when black.
TEST(GgxMultiscatter, FresnelColourFactor) {
  const float e_avg = ggx_average_albedo(0.36f);
  EXPECT_GT(e_avg, 0.7f);
  EXPECT_LT(e_avg, 0.9f);
  const Spectrum f = ggx_multiscatter::multiscatter_fresnel(Spectrum(1.0f, 0.5f, 0.0f), e_avg);
  EXPECT_NEAR(f.x, 1.0f, 1e-6f);
  EXPECT_NEAR(f.y, 0.25f * e_avg / (1.0f - 0.5f * (1.0f - e_avg)), 1e-6f);
  EXPECT_LT(f.y, 0.5f);
  EXPECT_EQ(f.z, 0.0f);
}

// Directions of cosine mu towards several azimuths about the normal (an anisotropic lobe's albedo
// depends on it).
std::vector<Vec3f> azimuths(float mu) {
  std::vector<Vec3f> out;
  for (float phi : {0.0f, 0.5f, 1.0f, 1.6f, 2.4f}) out.push_back(direction(mu, phi));
  return out;
}

// Anisotropic GGX with the lobe compensated as the isotropic one of the widths' root mean square:
// the white pair reflects 0.88 - 1.06 of the light from every direction (measured; the azimuth
// the albedo depends on is not modelled), where the lobe alone keeps as little as 0.57 and the
// compensation at sqrt(alpha_x alpha_y) brings 0.64 - 1.00.
TEST(GgxMultiscatter, AnisotropicWhiteFurnace) {
  const float widths[][2] = {
      {0.36f * 0.4f, 0.36f / 0.4f}, {0.2f, 0.6f}, {1.0f, 0.5f}, {0.05f, 0.9f}, {0.05f, 0.3f}};
  for (const auto& w : widths)
    for (float mu : {1.0f, 0.7f, 0.4f, 0.15f})
      for (const Vec3f wi : azimuths(mu)) {
        const Closure g = aniso_ggx(w[0], w[1], 0.7f);
        const Closure m = ggx_multiscatter::lobe_of(g, Spectrum(1.0f), Spectrum(1.0f));
        EXPECT_NEAR(m.alpha, std::sqrt(0.5f * (w[0] * w[0] + w[1] * w[1])), 1e-6f);
        const double e = albedo(set_of({g, m}), wi, 60000);
        EXPECT_NEAR(e, 0.97, 0.095) << w[0] << " x " << w[1] << " wi " << wi.x << " " << wi.y << " "
                                    << wi.z << " single " << albedo(set_of({g}), wi);
      }
}

// A one-node material with the Multiscatter GGX distribution, roughness r, colour c, anisotropy
// a about a constant tangent.
ClosureSet multiscatter_material(ShaderNodeKind kind, float r, Spectrum c, float a = 0.0f) {
  ShaderNode n;
  n.kind = kind;
  n.color = ColorInput(c);
  n.roughness = FloatInput(r);
  n.metallic = FloatInput(1.0f);
  n.anisotropy = FloatInput(a);
  n.tangent.source = TangentInput::Source::Vector;
  n.tangent.vector = ColorInput(Spectrum(1.0f, 0.0f, 0.0f));
  n.distribution = MicrofacetDistribution::MultiscatterGGX;
  return one_node_closures(n);
}

// The Glossy BSDF: its GGX lobe, coloured, and the compensation of Kulla-Conty's colour for
// F_avg = the colour; white, the pair reflects all light.
TEST(GgxMultiscatter, GlossyNodeAddsTheLobe) {
  const Spectrum c(1.0f, 0.5f, 0.2f);
  const ClosureSet s = multiscatter_material(ShaderNodeKind::Glossy, 0.6f, c);
  ASSERT_EQ(s.count(), 2);
  EXPECT_EQ(s[0].type, ClosureType::GGXReflection);
  EXPECT_EQ(s[0].distribution, MicrofacetDistribution::GGX);
  EXPECT_EQ(s[1].type, ClosureType::GGXMultiscatter);
  EXPECT_NEAR(s[1].alpha, 0.36f, 1e-6f);
  const Spectrum f = ggx_multiscatter::multiscatter_fresnel(c, ggx_average_albedo(0.36f));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s[1].weight[k], f[k], 1e-6f);
  for (float mu : kIncidentCos)
    EXPECT_NEAR(
        albedo(multiscatter_material(ShaderNodeKind::Glossy, 0.6f, Spectrum(1.0f)), incident(mu)),
        1.0, 0.02);
}

// Principled, white metal: Fresnel 1 at every angle, so the specular pair reflects all light.
TEST(GgxMultiscatter, PrincipledWhiteMetalPassesTheFurnace) {
  for (float r : kRoughness)
    for (float mu : kIncidentCos) {
      const ClosureSet s = multiscatter_material(ShaderNodeKind::Principled, r, Spectrum(1.0f));
      ASSERT_EQ(s.count(), 2);
      EXPECT_EQ(s[1].type, ClosureType::GGXMultiscatter);
      EXPECT_NEAR(albedo(s, incident(mu)), 1.0, 0.02) << "roughness " << r << " cos_i " << mu;
    }
}

// The Anisotropic BSDF: its anisotropic GGX lobe and the compensation of the widths' root mean
// square; and Principled with anisotropy: a white metal passes the furnace from several azimuths.
TEST(GgxMultiscatter, AnisotropicNodesAddTheLobe) {
  const Spectrum c(1.0f, 0.5f, 0.2f);
  const ClosureSet s = multiscatter_material(ShaderNodeKind::Anisotropic, 0.6f, c, 0.6f);
  ASSERT_EQ(s.count(), 2);
  EXPECT_EQ(s[0].type, ClosureType::GGXReflection);
  EXPECT_EQ(s[0].distribution, MicrofacetDistribution::GGX);
  EXPECT_NEAR(s[0].alpha, 0.36f * 0.4f, 1e-6f);
  EXPECT_NEAR(s[0].alpha_y, 0.36f / 0.4f, 1e-6f);
  EXPECT_EQ(s[1].type, ClosureType::GGXMultiscatter);
  const float rms = std::sqrt(0.5f * (s[0].alpha * s[0].alpha + s[0].alpha_y * s[0].alpha_y));
  EXPECT_NEAR(s[1].alpha, rms, 1e-6f);
  const Spectrum f = ggx_multiscatter::multiscatter_fresnel(c, ggx_average_albedo(rms));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s[1].weight[k], f[k], 1e-6f);
  for (float mu : {1.0f, 0.4f, -0.5f})
    for (const Vec3f wi : azimuths(mu)) {
      EXPECT_NEAR(
          albedo(multiscatter_material(ShaderNodeKind::Anisotropic, 0.6f, Spectrum(1.0f), 0.6f), wi,
                 60000),
          0.97, 0.095);
      const ClosureSet p =
          multiscatter_material(ShaderNodeKind::Principled, 0.6f, Spectrum(1.0f), 0.8f);
      ASSERT_EQ(p.count(), 2);
      EXPECT_TRUE(is_anisotropic(p[0]));
      EXPECT_NEAR(p[1].alpha,
                  std::sqrt(0.5f * (p[0].alpha * p[0].alpha + p[0].alpha_y * p[0].alpha_y)), 1e-6f);
      EXPECT_NEAR(albedo(p, wi, 60000), 0.97, 0.095);
    }
}

}  // namespace
}  // namespace gdpt::test
