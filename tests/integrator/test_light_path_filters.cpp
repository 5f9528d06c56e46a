// Cycles' Filter Glossy and caustics rules (integrators/common/light_path_filters.h) on closure
// sets, and the path state they read (PathState::scattered): the blur roughness against Cycles'
// formula sqrt(1 - pdf / blur_glossy) / 2, which lobes (or glass parts) each toggle drops, and
// that nothing changes with the rules off or on the camera path.
#include <gtest/gtest.h>

#include <cmath>

#include "integrators/common/light_path_filters.h"

namespace gdpt {
namespace {

Closure lobe(ClosureType type, float alpha, FresnelMode fresnel = FresnelMode::None) {
  Closure c;
  c.type = type;
  c.alpha = alpha;
  c.fresnel = fresnel;
  return c;
}

// Lambert, Glossy (alpha 0.01), Clearcoat (0.02), Glass (0), Refraction (0.05), Velvet (0.3).
ClosureSet mixed_set() {
  ClosureSet s;
  s.add(lobe(ClosureType::Lambert, 0.0f));
  s.add(lobe(ClosureType::GGXReflection, 0.01f));
  s.add(lobe(ClosureType::Clearcoat, 0.02f));
  s.add(lobe(ClosureType::GGXDielectric, 0.0f, FresnelMode::Dielectric));
  s.add(lobe(ClosureType::GGXDielectric, 0.05f, FresnelMode::RefractionOnly));
  s.add(lobe(ClosureType::Velvet, 0.3f));
  return s;
}

BsdfSample sample(uint8_t lobe_flags, float pdf) {
  BsdfSample bs;
  bs.lobe = lobe_flags;
  bs.pdf = pdf;
  bs.valid = true;
  return bs;
}

// The path state after one diffuse bounce sampled with density `pdf`.
PathState after_diffuse_bounce(float pdf) {
  PathState st;
  st.count_event(false, kRayDiffuse, kLobeReflection | kLobeDiffuse);
  st.scattered(sample(kLobeDiffuse | kLobeReflection, pdf));
  return st;
}

TEST(LightPathFilters, OffByDefaultAndOnTheCameraPath) {
  RenderSettings s;
  EXPECT_FALSE(LightPathFilters(s).enabled());
  s.blur_glossy = 1.0f;
  s.caustics_reflective = s.caustics_refractive = false;
  const LightPathFilters f(s);
  EXPECT_TRUE(f.enabled());
  EXPECT_FALSE(f.active(PathState{}));  // the camera path: no bounce yet
}

TEST(LightPathFilters, FilterGlossyRaisesGlossyAlphaAsCycles) {
  RenderSettings s;
  s.blur_glossy = 2.0f;
  const LightPathFilters f(s);
  PathState st = after_diffuse_bounce(0.5f);
  st.count_event(false, kRayGlossy, kLobeReflection | kLobeGlossy);
  st.scattered(sample(kLobeGlossy | kLobeReflection, 30.0f));  // a higher density: min stays
  EXPECT_FLOAT_EQ(st.min_ray_pdf, 0.5f);
  const float want = 0.5f * std::sqrt(1.0f - 0.5f / 2.0f);
  EXPECT_FLOAT_EQ(f.blur_alpha(st), want);
  ClosureSet set = mixed_set();
  f.apply(st, set, false);
  ASSERT_EQ(set.count(), 6);
  EXPECT_EQ(set[0].alpha, 0.0f);  // Lambert
  EXPECT_FLOAT_EQ(set[1].alpha, want);
  EXPECT_FLOAT_EQ(set[2].alpha, want);
  EXPECT_FLOAT_EQ(set[3].alpha, want);  // the smooth glass becomes rough
  EXPECT_FLOAT_EQ(set[4].alpha, want);
  EXPECT_EQ(set[5].alpha, 0.3f);  // Velvet: Cycles does not blur it
  // Delta bounces do not count; a density over blur_glossy blurs nothing.
  PathState sharp;
  sharp.count_event(false, kRayGlossy, kLobeReflection | kLobeGlossy);
  sharp.scattered(sample(kLobeGlossy | kLobeReflection | kLobeDelta, 0.01f));
  EXPECT_FALSE(f.active(sharp));
  PathState dense;
  dense.count_event(false, kRayGlossy, kLobeReflection | kLobeGlossy);
  dense.scattered(sample(kLobeGlossy | kLobeReflection, 2.5f));
  EXPECT_EQ(f.blur_alpha(dense), 0.0f);
  // A rougher lobe keeps its roughness.
  ClosureSet rough;
  rough.add(lobe(ClosureType::GGXReflection, 0.8f));
  f.apply(st, rough, false);
  EXPECT_EQ(rough[0].alpha, 0.8f);
}

// On a shadow caustics caster the smooth glass and refraction lobes stay sharp (manifold NEE
// connects through them smooth); glossy reflections and rough lobes blur as anywhere.
TEST(LightPathFilters, ShadowCausticsCastersKeepSmoothGlassSharp) {
  RenderSettings s;
  s.blur_glossy = 2.0f;
  const LightPathFilters f(s);
  const PathState st = after_diffuse_bounce(0.5f);
  const float want = f.blur_alpha(st);
  ASSERT_GT(want, 0.0f);
  ClosureSet set = mixed_set();
  set.add(lobe(ClosureType::GGXDielectric, 0.0f, FresnelMode::RefractionOnly));
  f.apply(st, set, true);
  EXPECT_FLOAT_EQ(set[1].alpha, want);  // glossy reflection
  EXPECT_FLOAT_EQ(set[2].alpha, want);  // clearcoat
  EXPECT_EQ(set[3].alpha, 0.0f);        // smooth glass
  EXPECT_FLOAT_EQ(set[4].alpha, want);  // rough refraction
  EXPECT_EQ(set[6].alpha, 0.0f);        // smooth refraction
}

int count_type(const ClosureSet& s, ClosureType t, FresnelMode fresnel) {
  int n = 0;
  for (int i = 0; i < s.count(); ++i) n += s[i].type == t && s[i].fresnel == fresnel;
  return n;
}

TEST(LightPathFilters, CausticsTogglesDropLobesAfterADiffuseBounce) {
  PathState after_diffuse = after_diffuse_bounce(0.3f), after_glossy;
  after_glossy.count_event(false, kRayGlossy, kLobeReflection | kLobeGlossy);
  after_glossy.scattered(sample(kLobeGlossy | kLobeReflection, 0.3f));
  // A transparent crossing keeps the flag (no scattered() call).
  after_diffuse.count_event(true, kRayDiffuse, 0);
  EXPECT_TRUE(after_diffuse.diffuse_ray);
  EXPECT_FALSE(after_glossy.diffuse_ray);

  struct Case {
    bool reflective, refractive;
    int left;  // lobes kept after a diffuse bounce
    bool glossy, clearcoat, glass, refraction;
  };
  const Case cases[] = {{true, true, 6, true, true, true, true},
                        {false, true, 4, false, false, true, true},
                        {true, false, 5, true, true, true, false},
                        {false, false, 2, false, false, false, false}};
  for (const Case& k : cases) {
    RenderSettings s;
    s.caustics_reflective = k.reflective;
    s.caustics_refractive = k.refractive;
    const LightPathFilters f(s);
    ClosureSet set = mixed_set();
    f.apply(after_diffuse, set, false);
    EXPECT_EQ(set.count(), k.left) << k.reflective << k.refractive;
    EXPECT_EQ(count_type(set, ClosureType::GGXReflection, FresnelMode::None), int(k.glossy));
    EXPECT_EQ(count_type(set, ClosureType::Clearcoat, FresnelMode::None), int(k.clearcoat));
    EXPECT_EQ(count_type(set, ClosureType::GGXDielectric, FresnelMode::Dielectric), int(k.glass));
    EXPECT_EQ(count_type(set, ClosureType::GGXDielectric, FresnelMode::RefractionOnly),
              int(k.refraction));
    // The glass lobe left with one toggle off has lost that part alone (Cycles' split).
    for (int i = 0; i < set.count(); ++i)
      if (set[i].type == ClosureType::GGXDielectric && set[i].fresnel == FresnelMode::Dielectric) {
        EXPECT_EQ(set[i].drop_reflection, !k.reflective);
        EXPECT_EQ(set[i].drop_refraction, !k.refractive);
      }
    EXPECT_EQ(set[0].type, ClosureType::Lambert);  // order kept
    // Multiscatter GGX glass: Cycles' one closure, kept whole unless both toggles are off.
    ClosureSet multiscatter;
    Closure g = lobe(ClosureType::GGXDielectric, 0.3f, FresnelMode::Dielectric);
    g.multiscatter = true;
    multiscatter.add(g);
    f.apply(after_diffuse, multiscatter, false);
    ASSERT_EQ(multiscatter.count(), int(k.reflective || k.refractive));
    if (multiscatter.count() == 1) {
      EXPECT_FALSE(multiscatter[0].drop_reflection);
      EXPECT_FALSE(multiscatter[0].drop_refraction);
    }
    ClosureSet untouched = mixed_set();
    f.apply(after_glossy, untouched, false);
    EXPECT_EQ(untouched.count(), 6);
  }
}

}  // namespace
}  // namespace gdpt
