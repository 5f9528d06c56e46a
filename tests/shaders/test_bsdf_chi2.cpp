// Chi-square goodness-of-fit of ClosureSet::sample() against ClosureSet::pdf() for every lobe,
// at several roughnesses and incident angles (normal, oblique, grazing, below the surface), and
// for mixtures; plus sample().value == eval() and sample().pdf == pdf() on every sample.
#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "testing/chi2.h"
#include "tests/shaders/lobe_factory.h"

namespace gdpt::test {
namespace {

struct Case {
  std::string name;
  ClosureSet set;
};

std::vector<Case> lobe_cases() {
  std::vector<Case> cases;
  cases.push_back({"Lambert", set_of({lambert()})});
  cases.push_back({"OrenNayar05", set_of({oren_nayar(0.5f)})});
  cases.push_back({"OrenNayar1", set_of({oren_nayar(1.0f)})});
  cases.push_back({"PrincipledDiffuse05", set_of({principled_diffuse(0.5f)})});
  cases.push_back({"PrincipledSheen", set_of({principled_sheen()})});
  cases.push_back({"Translucent", set_of({translucent()})});
  for (float a : {0.0f, 0.3f}) {  // Refraction BSDF: refraction alone, smooth and rough
    cases.push_back(
        {"Refraction" + std::to_string(int(a * 100 + 0.5f)), set_of({refraction(a, 1.5f)})});
  }
  cases.push_back({"BeckmannRefraction30", set_of({beckmann(refraction(0.3f, 1.5f))})});
  cases.push_back({"Velvet02", set_of({velvet(0.2f)})});
  cases.push_back({"Velvet1", set_of({velvet(1.0f)})});
  cases.push_back(
      {"MixLambertTranslucentVelvet", set_of({lambert(Spectrum(0.3f)), translucent(Spectrum(0.5f)),
                                              velvet(0.5f, Spectrum(0.4f))})});
  for (float a : {0.05f, 0.2f, 0.5f, 1.0f}) {
    const std::string s = std::to_string(int(a * 100 + 0.5f));
    cases.push_back({"GGX" + s, set_of({ggx(a)})});
    cases.push_back(
        {"GGXPrincipled" + s, set_of({ggx_principled(a, 1.5f, Spectrum(0.9f, 0.5f, 0.1f))})});
    cases.push_back({"Glass" + s, set_of({glass(a, 1.5f)})});
    cases.push_back({"Clearcoat" + s, set_of({clearcoat(a)})});
    cases.push_back({"Beckmann" + s, set_of({beckmann(ggx(a))})});
    cases.push_back({"BeckmannGlass" + s, set_of({beckmann(glass(a, 1.5f))})});
    cases.push_back({"AshikhminShirley" + s, set_of({ashikhmin_shirley(ggx(a))})});
    cases.push_back({"MultiscatterLobe" + s, set_of({multiscatter_of(ggx(a))})});
    const Spectrum tint(0.9f, 0.6f, 0.2f);
    cases.push_back({"MultiscatterGGX" + s, set_of({ggx(a, tint), multiscatter_of(ggx(a), tint)})});
    cases.push_back(
        {"MultiscatterGlass" + s, set_of({multiscatter_glass(glass(a, 1.5f, tint), tint)})});
  }
  // Ashikhmin-Shirley anisotropic: the quadrant-wise azimuth sampler, either width the wider.
  cases.push_back(
      {"AshikhminShirley05x40", set_of({ashikhmin_shirley(aniso_ggx(0.05f, 0.4f, 0.3f))})});
  cases.push_back(
      {"AshikhminShirley50x10", set_of({ashikhmin_shirley(aniso_ggx(0.5f, 0.1f, 2.0f))})});
  // Glass with one part dropped (Cycles' caustics toggles): the other part alone.
  for (const bool reflection : {true, false}) {
    Closure g = glass(0.2f, 1.5f);
    (reflection ? g.drop_refraction : g.drop_reflection) = true;
    cases.push_back({reflection ? "GlassReflectionPart20" : "GlassRefractionPart20", set_of({g})});
  }
  // Anisotropic GGX: narrow across a rotated tangent, wide along it, and the reverse.
  cases.push_back({"AnisoGGX05x40", set_of({aniso_ggx(0.05f, 0.4f, 0.3f)})});
  cases.push_back({"AnisoGGX50x10", set_of({aniso_ggx(0.5f, 0.1f, 2.0f)})});
  // Anisotropic Beckmann: the visible slopes of the configuration stretched by both widths.
  cases.push_back({"AnisoBeckmann05x40", set_of({beckmann(aniso_ggx(0.05f, 0.4f, 0.3f))})});
  cases.push_back({"AnisoBeckmann50x10", set_of({beckmann(aniso_ggx(0.5f, 0.1f, 2.0f))})});
  {
    Closure a = aniso_ggx(0.3f, 0.08f, 1.0f);
    a.fresnel = FresnelMode::PrincipledV1;
    a.ior = 1.5f;
    a.f0 = Spectrum(0.9f, 0.5f, 0.1f);
    cases.push_back({"AnisoGGXPrincipled30x8", set_of({a})});
  }
  // Principled-like glass: tinted refraction, Fresnel-coloured reflection.
  {
    Closure g = glass(0.2f, 1.45f);
    g.fresnel = FresnelMode::PrincipledV1;
    g.f0 = Spectrum(0.8f, 0.6f, 0.4f);
    g.transmission_tint = Spectrum(0.2f, 0.9f, 0.3f);
    cases.push_back({"GlassPrincipled20", set_of({g})});
  }
  // Mixtures: diffuse + glossy (Principled-like), and a set with a delta lobe.
  cases.push_back({"MixDiffuseGlossy", set_of({principled_diffuse(0.3f, Spectrum(0.6f, 0.3f, 0.2f)),
                                               ggx_principled(0.04f, 1.5f, Spectrum(0.04f))})});
  cases.push_back({"MixDiffuseSheen", set_of({principled_diffuse(0.5f, Spectrum(0.05f)),
                                              principled_sheen(Spectrum(0.8f, 0.7f, 0.6f))})});
  cases.push_back({"MixLambertGlassTransparent",
                   set_of({lambert(Spectrum(0.3f)), glass(0.3f, 1.33f, Spectrum(0.7f)),
                           transparent(Spectrum(0.2f))})});
  cases.push_back(
      {"MixOrenGGXSmoothGlass", set_of({oren_nayar(0.7f, Spectrum(0.5f)), ggx(0.5f, Spectrum(0.5f)),
                                        glass(0.0f, 1.5f, Spectrum(0.5f))})});
  // Lobes about their own normal (a clearcoat on the interpolated normal under a bump), alone
  // and mixed with a lobe about the shading normal.
  cases.push_back({"GGXOwnNormal20", set_of({kept(ggx(0.2f))}, Vec3f(0.4f, -0.2f, 0.9f))});
  cases.push_back(
      {"AnisoGGXOwnNormal", set_of({kept(aniso_ggx(0.1f, 0.4f, 0.5f))}, Vec3f(0.4f, -0.2f, 0.9f))});
  cases.push_back(
      {"MixDiffuseCoatOwnNormal",
       set_of({principled_diffuse(0.5f, Spectrum(0.4f, 0.3f, 0.2f)), kept(clearcoat(0.05f))},
              Vec3f(-0.3f, 0.1f, 0.95f))});
  return cases;
}

const float kIncidentCos[] = {1.0f, 0.7f, 0.2f, 0.02f, -0.6f, -0.15f};
constexpr int kSamples = 100000;

struct Param {
  int case_index;
  int angle_index;
};

class BsdfChi2 : public ::testing::TestWithParam<Param> {};

TEST_P(BsdfChi2, SampleMatchesPdf) {
  static const std::vector<Case> cases = lobe_cases();
  const Case& c = cases[size_t(GetParam().case_index)];
  const Vec3f wi = incident(kIncidentCos[GetParam().angle_index]);
  const int tests = int(cases.size() * std::size(kIncidentCos));
  const ClosureSet& set = c.set;

  double max_value_err = 0.0, max_pdf_err = 0.0;
  auto sampler = [&](Pcg32& rng) -> std::optional<Vec3f> {
    const float ul = rng.uniform();
    const Vec2f u(rng.uniform(), rng.uniform());
    const BsdfSample s = set.sample(wi, ul, u);
    if (!s.valid || s.is_delta()) return std::nullopt;
    EXPECT_TRUE(is_finite(s.value) && std::isfinite(s.pdf));
    // The sampled value and density are the mixture's eval() and pdf().
    const Spectrum e = set.eval(wi, s.wo);
    const float p = set.pdf(wi, s.wo);
    for (int k = 0; k < 3; ++k)
      max_value_err = std::max(max_value_err, std::fabs(double(e[k] - s.value[k])) /
                                                  std::max(1e-4, double(std::fabs(e[k]))));
    max_pdf_err = std::max(max_pdf_err, std::fabs(double(p - s.pdf)) / std::max(1e-4, double(p)));
    return s.wo;
  };
  auto density = [&](Vec3f wo) { return double(set.pdf(wi, wo)); };
  const Chi2Result r = chi2_test(sampler, density, kSamples, 1234 + GetParam().angle_index);
  const double level = sidak(0.01, tests);
  RecordProperty("p_value", std::to_string(r.p_value));  // in --gtest_output=xml
  EXPECT_GE(r.p_value, level) << c.name << " cos_i=" << wi.z << ": chi2=" << r.chi2
                              << " dof=" << r.dof << " pdf mass=" << r.pdf_mass
                              << " sampled mass=" << r.sampled_mass << " " << r.message;
  EXPECT_LT(max_value_err, 2e-3) << c.name;
  EXPECT_LT(max_pdf_err, 2e-3) << c.name;
  // The density never claims more than the sampler delivers (or vice versa) overall.
  EXPECT_NEAR(r.pdf_mass, r.sampled_mass, 0.01) << c.name;
}

std::vector<Param> all_params() {
  std::vector<Param> p;
  const int n = int(lobe_cases().size());
  for (int c = 0; c < n; ++c)
    for (int a = 0; a < int(std::size(kIncidentCos)); ++a) p.push_back({c, a});
  return p;
}

std::string param_name(const ::testing::TestParamInfo<Param>& info) {
  static const std::vector<Case> cases = lobe_cases();
  static const char* angles[] = {"Normal",  "Oblique",      "Shallow",
                                 "Grazing", "BelowOblique", "BelowShallow"};
  return cases[size_t(info.param.case_index)].name + "_" + angles[info.param.angle_index];
}

INSTANTIATE_TEST_SUITE_P(AllLobes, BsdfChi2, ::testing::ValuesIn(all_params()), param_name);

}  // namespace
}  // namespace gdpt::test
