// BSDF properties with analytic or independent oracles: energy (albedo) against quadrature of
// eval(), reciprocity, Fresnel limits, smooth-glass energy and Snell's law, closed-form values
// of the diffuse models, ClosureSet bookkeeping, and no NaN/Inf in degenerate configurations.
#include <gtest/gtest.h>

#include "shaders/fresnel.h"
#include "testing/chi2.h"
#include "tests/shaders/lobe_factory.h"

namespace gdpt::test {
namespace {

// Integral of eval(wi, .) over the sphere (the directional albedo), by adaptive quadrature.
double albedo_quadrature(const ClosureSet& set, Vec3f wi, int channel = 1) {
  Integrator2D integ([&](double theta, double phi) {
    return double(set.eval(wi, direction(std::cos(theta), phi))[channel]) * std::sin(theta);
  });
  double sum = 0.0;
  // Split at the equator and in a few phi wedges so lobes on either side are resolved.
  for (int h = 0; h < 2; ++h)
    for (int k = 0; k < 8; ++k)
      sum += integ.integrate(h * M_PI / 2, (h + 1) * M_PI / 2, k * M_PI / 4, (k + 1) * M_PI / 4,
                             1e-8, 3, 9);
  return sum;
}

// Mean sample weight (including delta lobes): the MC estimate of the albedo.
double albedo_mc(const ClosureSet& set, Vec3f wi, int n, int channel = 1) {
  return sampled_albedo(set, wi, n, 7, channel);
}

TEST(BsdfEnergy, WhiteLambertAlbedoIsOne) {
  const ClosureSet set = set_of({lambert()});
  for (float c : {1.0f, 0.5f, 0.05f, -0.7f}) {
    const Vec3f wi = incident(c);
    EXPECT_NEAR(albedo_quadrature(set, wi), 1.0, 1e-4) << c;
    EXPECT_NEAR(albedo_mc(set, wi, 20000), 1.0, 1e-6) << c;
  }
}

// The MC estimate from sample weights must equal the quadrature of eval for every lobe: this
// ties sample() to eval() independently of pdf().
TEST(BsdfEnergy, SampleWeightsIntegrateEval) {
  const ClosureSet sets[] = {
      set_of({oren_nayar(0.8f)}),
      set_of({principled_diffuse(0.7f)}),
      set_of({ggx(0.3f)}),
      set_of({ggx(1.0f)}),
      set_of({ggx_principled(0.25f, 1.5f, Spectrum(0.9f, 0.6f, 0.3f))}),
      set_of({glass(0.3f, 1.5f)}),
      set_of({principled_diffuse(0.5f, Spectrum(0.5f)), ggx(0.4f, Spectrum(0.5f))}),
      set_of({beckmann(ggx(0.3f))}),
      set_of({beckmann(ggx(1.0f))}),
      set_of({beckmann(glass(0.3f, 1.5f))}),
      set_of({aniso_ggx(0.05f, 0.6f, 0.4f)}),
      set_of({ashikhmin_shirley(ggx(0.3f))}),
      set_of({ashikhmin_shirley(ggx(1.0f))}),
      set_of({ashikhmin_shirley(aniso_ggx(0.05f, 0.6f, 0.4f))}),
  };
  for (size_t i = 0; i < std::size(sets); ++i) {
    for (float c : {0.9f, 0.4f, -0.5f}) {
      const Vec3f wi = incident(c);
      const double q = albedo_quadrature(sets[i], wi);
      const double mc = albedo_mc(sets[i], wi, 200000);
      EXPECT_NEAR(mc, q, 0.01 * q + 1e-3) << "set " << i << " cos_i " << c;
      // Burley's diffuse (set 1) is not energy conserving (retro-reflection); the others are.
      if (i != 1) {
        EXPECT_LE(q, 1.0 + 1e-3) << "set " << i << " gains energy";
      }
    }
  }
}

TEST(BsdfEnergy, GgxWhiteFurnaceLossIsSmallForSmoothAndLargerForRough) {
  // Single-scattering GGX loses energy with roughness (no multiple scattering, as Cycles' GGX).
  const Vec3f wi = incident(0.8f);
  const double smooth = albedo_quadrature(set_of({ggx(0.05f)}), wi);
  const double rough = albedo_quadrature(set_of({ggx(1.0f)}), wi);
  EXPECT_NEAR(smooth, 1.0, 0.01);
  EXPECT_LT(rough, smooth - 0.2);
}

TEST(BsdfReciprocity, ReflectionLobesAreSymmetric) {
  const Closure lobes[] = {lambert(),
                           oren_nayar(0.6f),
                           principled_diffuse(0.8f),
                           principled_sheen(),
                           ggx(0.3f),
                           ggx_principled(0.15f, 1.6f, Spectrum(0.7f, 0.4f, 0.2f)),
                           clearcoat(0.1f),
                           beckmann(ggx(0.3f)),
                           aniso_ggx(0.08f, 0.5f, 1.2f),
                           ashikhmin_shirley(ggx(0.3f)),
                           ashikhmin_shirley(aniso_ggx(0.08f, 0.5f, 1.2f))};
  Pcg32 rng(3);
  for (const Closure& c : lobes) {
    const ClosureSet set = set_of({c});
    for (int i = 0; i < 200; ++i) {
      const float side = i % 2 ? 1.0f : -1.0f;  // both sides of the surface
      Vec3f a = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
      Vec3f b = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
      a.z *= side;
      b.z *= side;
      const Spectrum fab = set.eval(a, b) / std::fabs(b.z);
      const Spectrum fba = set.eval(b, a) / std::fabs(a.z);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(fab[k], fba[k], 1e-4f * std::max(1.0f, fab[k])) << int(c.type);
    }
  }
}

TEST(BsdfReciprocity, GlassTransmissionCarriesEtaSquared) {
  // Without the 1/eta^2 radiance scaling (Cycles' convention) the microfacet BTDF satisfies
  // f(wi, wo) / (1 - F(wi)) = eta^2 f(wo, wi) / (1 - F(wo)), eta = n(wo side) / n(wi side).
  const float ior = 1.5f;
  for (const ClosureSet& set : {set_of({glass(0.3f, ior)}), set_of({beckmann(glass(0.3f, ior))})}) {
    Pcg32 rng(5);
    int checked = 0;
    for (int i = 0; i < 2000; ++i) {
      const Vec3f a = direction(0.1 + 0.9 * rng.uniform(), 2 * M_PI * rng.uniform());
      const Vec3f b = direction(-0.1 - 0.9 * rng.uniform(), 2 * M_PI * rng.uniform());
      const float fab = set.eval(a, b).y / std::fabs(b.z);
      const float fba = set.eval(b, a).y / std::fabs(a.z);
      // Cycles 3.4 splits by the Fresnel term at the shading normal: the reverse direction may be
      // beyond the critical angle (F = 1), where the lobe is not reciprocal at all.
      if (fab < 1e-6f || fresnel_dielectric(b.z, 1.0f / ior) >= 1.0f) continue;
      const float lhs = fab / (1.0f - fresnel_dielectric(a.z, ior));
      const float rhs = ior * ior * fba / (1.0f - fresnel_dielectric(b.z, 1.0f / ior));
      EXPECT_NEAR(lhs, rhs, 1e-3f * lhs);
      ++checked;
    }
    EXPECT_GT(checked, 100);
  }
}

TEST(Fresnel, NormalIncidenceAndKnownAngle) {
  for (float n : {1.33f, 1.5f, 2.4f}) {
    const float f0 = ((n - 1) / (n + 1)) * ((n - 1) / (n + 1));
    EXPECT_NEAR(fresnel_dielectric(1.0f, n), f0, 1e-6f);
    EXPECT_NEAR(fresnel_dielectric(1.0f, 1.0f / n), f0, 1e-6f);  // same from inside
  }
  // n = 1.5 at 45 degrees: Rs = 0.0920, Rp = 0.0085 (textbook values), mean 0.0503.
  EXPECT_NEAR(fresnel_dielectric(std::cos(float(M_PI) / 4), 1.5f), 0.0503f, 2e-4f);
  EXPECT_NEAR(fresnel_dielectric(0.0f, 1.5f), 1.0f, 1e-6f);  // grazing
  EXPECT_NEAR(fresnel_dielectric(0.3f, 1.0f), 0.0f, 1e-7f);  // index matched
}

TEST(Fresnel, TotalInternalReflectionBeyondCriticalAngle) {
  const float eta = 1.0f / 1.5f;                                      // leaving glass
  const float cos_critical = std::sqrt(1.0f - 1.0f / (1.5f * 1.5f));  // 0.745
  EXPECT_EQ(fresnel_dielectric(cos_critical - 1e-3f, eta), 1.0f);
  EXPECT_EQ(fresnel_dielectric(0.2f, eta), 1.0f);
  EXPECT_LT(fresnel_dielectric(cos_critical + 0.02f, eta), 1.0f);
  EXPECT_LT(fresnel_dielectric(0.9f, eta), 0.1f);
}

TEST(SmoothGlass, EnergyIsConservedAndDirectionsObeySnell) {
  const float ior = 1.5f;
  const ClosureSet set = set_of({glass(0.0f, ior)});
  EXPECT_TRUE(set.has_delta());
  EXPECT_EQ(set.roughness(), 0.0f);
  for (float c : {1.0f, 0.8f, 0.3f, 0.01f, -0.95f, -0.8f, -0.5f}) {
    const Vec3f wi = incident(c);
    const bool entering = c > 0;
    const float eta = entering ? ior : 1.0f / ior;
    const float fr = fresnel_dielectric(c, eta);
    double expected_weight = 0.0;  // sum over the two outcomes of probability * weight
    uint8_t seen = 0;
    for (float ul : {0.0f, 0.999f}) {
      const BsdfSample s = set.sample(wi, ul, Vec2f(0.5f, 0.5f));
      if (!s.valid || (s.lobe & seen)) continue;  // each outcome once
      seen |= s.lobe & (kLobeReflection | kLobeTransmission);
      ASSERT_TRUE(s.is_delta());
      expected_weight += s.pdf * s.weight().y;
      if (s.lobe & kLobeReflection) {
        EXPECT_NEAR(s.wo.z, wi.z, 1e-6f);
        EXPECT_NEAR(s.wo.x, -wi.x, 1e-6f);
        EXPECT_NEAR(s.pdf, fr, 1e-5f);  // white glass: reflection chosen with probability F
        EXPECT_EQ(s.eta, 1.0f);
      } else {
        const float sin_i = std::sqrt(1 - wi.z * wi.z), sin_o = std::sqrt(1 - s.wo.z * s.wo.z);
        EXPECT_NEAR(sin_o * eta, sin_i, 1e-5f);  // Snell
        EXPECT_LT(s.wo.z * wi.z, 0.0f);
        EXPECT_NEAR(s.eta, eta, 1e-6f);
        EXPECT_NEAR(s.weight().y, 1.0f, 1e-5f);  // no 1/eta^2: Cycles' convention
      }
    }
    EXPECT_NEAR(expected_weight, 1.0, 1e-5) << c;  // R + T = 1 for white glass
    if (c < 0 && std::fabs(c) < std::sqrt(1.0f - 1.0f / (ior * ior))) {
      EXPECT_EQ(fr, 1.0f);
    }
  }
}

TEST(SmoothGlass, TotalInternalReflectionReflectsEverything) {
  const ClosureSet set = set_of({glass(0.0f, 1.5f)});
  const Vec3f wi = incident(-0.5f);  // inside, beyond the critical angle (cos 0.745)
  for (float ul : {0.0f, 0.5f, 0.999f}) {
    const BsdfSample s = set.sample(wi, ul, Vec2f(0.3f, 0.7f));
    ASSERT_TRUE(s.valid);
    EXPECT_TRUE(s.lobe & kLobeReflection);
    EXPECT_NEAR(s.weight().x, 1.0f, 1e-6f);
    EXPECT_LT(s.wo.z, 0.0f);
  }
}

// Cycles' caustics toggles leave one of the glass BSDF's two closures: dropping a part keeps the
// other's values (weighted by F or 1 - F at the shading normal) and never samples the dropped one.
TEST(GlassParts, DroppingOnePartKeepsTheOther) {
  const float ior = 1.5f;
  for (const float alpha : {0.0f, 0.3f}) {
    const Closure whole = glass(alpha, ior);
    Closure refl = whole, refr = whole;
    refl.drop_refraction = true;
    refr.drop_reflection = true;
    const ClosureSet full = set_of({whole}), reflection = set_of({refl}),
                     refraction = set_of({refr});
    Pcg32 rng(11);
    for (int i = 0; i < 200; ++i) {
      const Vec3f wi = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
      const float fr = fresnel_dielectric(wi.z, ior);
      const Vec2f u(rng.uniform(), rng.uniform());
      const float choice = rng.uniform();
      const BsdfSample a = reflection.sample(wi, choice, u), b = refraction.sample(wi, choice, u);
      if (a.valid) {
        EXPECT_TRUE(a.lobe & kLobeReflection);
        if (alpha == 0.0f) {
          EXPECT_NEAR(a.weight().y, fr, 1e-5f);  // F, chosen always
        }
      }
      if (b.valid) {
        EXPECT_TRUE(b.lobe & kLobeTransmission);
        if (alpha == 0.0f) {
          EXPECT_NEAR(b.weight().y, 1.0f - fr, 1e-5f);
        }
      }
      if (alpha == 0.0f) continue;
      const Vec3f up = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
      const Vec3f down = direction(-0.05 - 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
      EXPECT_EQ(reflection.eval(wi, down).y, 0.0f);
      EXPECT_EQ(refraction.eval(wi, up).y, 0.0f);
      EXPECT_NEAR(reflection.eval(wi, up).y, full.eval(wi, up).y, 1e-6f);
      EXPECT_NEAR(refraction.eval(wi, down).y, full.eval(wi, down).y, 1e-6f);
    }
  }
}

TEST(DiffuseModels, ClosedFormValues) {
  const Vec3f n(0, 0, 1);
  const Vec3f wo = direction(0.5, 0.0);
  // Principled diffuse, roughness 1, wi = normal: F_v = 0, F_l = 0.5^5, RR = 1 + 0.5.
  {
    const ClosureSet s = set_of({principled_diffuse(1.0f)});
    const double fl = std::pow(0.5, 5), rr = 1.5;
    const double expected = 0.5 / M_PI * ((1 - 0.5 * fl) + rr * fl);
    EXPECT_NEAR(s.eval(n, wo).x, expected, 1e-6);
    EXPECT_NEAR(set_of({principled_diffuse(0.0f)}).eval(n, n).x, 1.0 / M_PI, 1e-6);
  }
  // Principled sheen (Cycles' form, no 1/pi): F(dot(wo, h)) cos_o; wi = normal and wo at 60
  // degrees give a 30-degree half angle; wi = wo gives F(1) = 0.
  {
    const ClosureSet s = set_of({principled_sheen(Spectrum(0.5f))});
    EXPECT_NEAR(s.eval(n, wo).x, 0.5 * std::pow(1.0 - std::cos(M_PI / 6), 5) * 0.5, 1e-7);
    EXPECT_EQ(s.eval(wo, wo).x, 0.0f);
    EXPECT_EQ(s.eval(n, Vec3f(wo.x, wo.y, -wo.z)).x, 0.0f);  // no transmission
  }
  // Oren-Nayar (Cycles' form), sigma = 1.
  {
    const ClosureSet s = set_of({oren_nayar(1.0f)});
    const double a = 1.0 / (M_PI + (3 * M_PI - 4) / 6), b = a;
    EXPECT_NEAR(s.eval(n, wo).x, 0.5 * a, 1e-6);  // s = dot - cos cos = 0
    const Vec3f w = direction(0.6, 1.0);
    const double t = (1.0 - 0.36) / 0.6;  // wi = wo: s = 1 - cos^2, divided by max(cos)
    EXPECT_NEAR(s.eval(w, w).x, 0.6 * (a + b * t), 1e-5);
  }
  // Two-sided: the same values from below the surface.
  {
    const ClosureSet s = set_of({oren_nayar(1.0f)});
    const Vec3f nb(0, 0, -1), wob(wo.x, wo.y, -wo.z);
    EXPECT_NEAR(s.eval(nb, wob).x, s.eval(n, wo).x, 1e-7);
    EXPECT_EQ(s.eval(nb, wo).x, 0.0f);  // other side of wi: nothing
  }
}

TEST(ClosureSet, AddDropsZeroAndWeakestLobes) {
  ClosureSet s;
  s.add(lambert(Spectrum(0.0f)));
  EXPECT_EQ(s.count(), 0);
  for (int i = 0; i < kMaxClosures; ++i) s.add(lambert(Spectrum(0.1f * (i + 1))));
  EXPECT_EQ(s.count(), kMaxClosures);
  s.add(lambert(Spectrum(0.05f)));  // weaker than all: dropped
  s.add(lambert(Spectrum(2.0f)));   // replaces the weakest (0.1)
  EXPECT_EQ(s.count(), kMaxClosures);
  float min_w = 10.0f, max_w = 0.0f;
  for (int i = 0; i < s.count(); ++i) {
    min_w = std::min(min_w, s[i].weight.x);
    max_w = std::max(max_w, s[i].weight.x);
  }
  EXPECT_FLOAT_EQ(min_w, 0.2f);
  EXPECT_FLOAT_EQ(max_w, 2.0f);
  s.add_emission(Spectrum(1, 2, 3));
  EXPECT_EQ(s.emission(), Spectrum(1, 2, 3));
  s.clear();
  EXPECT_EQ(s.count(), 0);
  EXPECT_TRUE(is_black(s.emission()));
}

TEST(ClosureSet, RoughnessClassification) {
  EXPECT_EQ(set_of({lambert()}).roughness(), 1.0f);
  EXPECT_FLOAT_EQ(set_of({lambert(), ggx(0.2f)}).roughness(), 0.2f);
  EXPECT_FLOAT_EQ(set_of({glass(0.04f, 1.5f), lambert()}).roughness(), 0.04f);
  EXPECT_EQ(set_of({glass(0.0f, 1.5f)}).roughness(), 0.0f);
  EXPECT_EQ(set_of({transparent()}).roughness(), 0.0f);
  EXPECT_EQ(set_of({transparent(), lambert()}).roughness(), 1.0f);
  EXPECT_FALSE(set_of({lambert(), ggx(0.2f)}).has_delta());
  EXPECT_TRUE(set_of({lambert(), ggx(0.0f)}).has_delta());
}

TEST(ClosureSet, SampleReportsLobeFlagsEtaAndRoughness) {
  const ClosureSet g = set_of({glass(0.3f, 1.5f)});
  Pcg32 rng(11);
  int refracted_in = 0, refracted_out = 0;
  for (int i = 0; i < 2000; ++i) {
    const float c = i % 2 ? 0.8f : -0.9f;
    const BsdfSample s = g.sample(incident(c), rng.uniform(), Vec2f(rng.uniform(), rng.uniform()));
    if (!s.valid || !(s.lobe & kLobeTransmission)) continue;
    EXPECT_TRUE(s.lobe & kLobeGlossy);
    EXPECT_FLOAT_EQ(s.roughness, 0.3f);
    if (c > 0) {
      EXPECT_FLOAT_EQ(s.eta, 1.5f);
      ++refracted_in;
    } else {
      EXPECT_FLOAT_EQ(s.eta, 1.0f / 1.5f);
      ++refracted_out;
    }
  }
  EXPECT_GT(refracted_in, 100);
  EXPECT_GT(refracted_out, 100);
  const BsdfSample t = set_of({transparent(Spectrum(0.5f))}).sample(incident(0.4f), 0.5f, {});
  EXPECT_TRUE(t.valid && t.is_delta());
  EXPECT_EQ(t.wo, -incident(0.4f));
  EXPECT_NEAR(t.weight().x, 0.5f, 1e-7f);
}

// Delta lobes that send wi the same way are one discrete event: sample() returns the sum of
// their values and of their selection times event probabilities whichever of them the lobe number
// picks, and delta_event() returns the same without a lobe number (G-PT's shift of a delta
// event). Two mirrors in one set are one mirror of their summed colour, probability 1.
TEST(ClosureSet, DeltaLobesOfOneDirectionAreOneEvent) {
  const Vec3f wi = incident(0.6f);
  const ClosureSet mirrors =
      set_of({ggx(0.0f, Spectrum(0.9f, 0.2f, 0.1f)), ggx(1e-4f, Spectrum(0.1f, 0.3f, 0.8f))});
  const BsdfSample event = mirrors.delta_event(wi, kLobeReflection);
  ASSERT_TRUE(event.valid && event.is_delta());
  EXPECT_NEAR(event.pdf, 1.0f, 1e-6f);
  EXPECT_NEAR(event.value.x, 1.0f, 1e-6f);
  EXPECT_NEAR(event.value.y, 0.5f, 1e-6f);
  EXPECT_NEAR(event.value.z, 0.9f, 1e-6f);
  EXPECT_FALSE(mirrors.delta_event(wi, kLobeTransmission).valid);
  // A mirror and smooth glass: their reflections are one event, the refraction another.
  const ClosureSet mirror_glass = set_of({ggx(0.0f, Spectrum(0.5f)), glass(0.0f, 1.5f)});
  const float f = fresnel_dielectric(0.6f, 1.5f);
  const BsdfSample reflection = mirror_glass.delta_event(wi, kLobeReflection);
  const BsdfSample refraction = mirror_glass.delta_event(wi, kLobeTransmission);
  ASSERT_TRUE(reflection.valid && refraction.valid);
  EXPECT_NEAR(reflection.value.y, 0.5f + f, 1e-6f);
  EXPECT_NEAR(refraction.value.y, 1.0f - f, 1e-6f);
  EXPECT_NEAR(reflection.pdf + refraction.pdf, 1.0f, 1e-6f);
  for (const ClosureSet* set : {&mirrors, &mirror_glass})
    for (float u_lobe : {0.01f, 0.3f, 0.6f, 0.99f}) {
      const BsdfSample s = set->sample(wi, u_lobe, Vec2f(0.5f, 0.5f));
      ASSERT_TRUE(s.valid && s.is_delta());
      const BsdfSample e = set->delta_event(wi, s.lobe & (kLobeReflection | kLobeTransmission));
      EXPECT_EQ(s.wo, e.wo);
      EXPECT_NEAR(s.pdf, e.pdf, 1e-6f) << u_lobe;
      EXPECT_NEAR(s.value.y, e.value.y, 1e-6f) << u_lobe;
    }
  // Straight through and refracted: two transmissions, so the event names no direction.
  EXPECT_FALSE(set_of({transparent(), glass(0.0f, 1.5f)}).delta_event(wi, kLobeTransmission).valid);
  // Mirrors about two normals (one lobe keeps a tilted interpolated normal): two reflections.
  const ClosureSet tilted = set_of({ggx(0.0f), kept(ggx(0.0f))}, Vec3f(0.2f, 0.0f, 1.0f));
  EXPECT_FALSE(tilted.delta_event(wi, kLobeReflection).valid);
  EXPECT_TRUE(set_of({ggx(0.0f)}, Vec3f(0.2f, 0.0f, 1.0f)).delta_event(wi, kLobeReflection).valid);
}

// Bump shadowing scales the diffuse lobes' values by Cycles' term of g = cos(n0, wo) / (cos(n,
// wo) cos(n0, n)) (n = +z) and leaves glossy lobes and all densities alone; sampling returns the
// same values as evaluation.
TEST(ClosureSet, BumpShadowingScalesDiffuseValuesOnly) {
  const Vec3f n0 = normalize(Vec3f(0.3f, 0.0f, 1.0f));  // the unperturbed normal
  auto term = [&](Vec3f wo) {
    const float g = dot(n0, wo) / (wo.z * n0.z);
    return g >= 1.0f ? 1.0f : g < 0.0f ? 0.0f : -g * g * g + g * g + g;
  };
  for (const bool single : {true, false}) {
    const ClosureSet plain =
        single ? set_of({lambert(Spectrum(0.7f))}) : set_of({lambert(Spectrum(0.7f)), ggx(0.3f)});
    ClosureSet bumped = plain;
    bumped.set_bump_shadowing(n0);
    const ClosureSet glossy = set_of({ggx(0.3f)});
    Pcg32 rng(3);
    int scaled = 0;
    for (int i = 0; i < 500; ++i) {
      const Vec3f wi = incident(0.2f + 0.8f * rng.uniform());
      const float phi = 6.2831853f * rng.uniform(), z = rng.uniform();
      const Vec3f wo(std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z);
      float pdf_plain, pdf_bumped;
      const Spectrum f = plain.eval_pdf(wi, wo, pdf_plain);
      const Spectrum fb = bumped.eval_pdf(wi, wo, pdf_bumped);
      const Spectrum fg = single ? Spectrum(0.0f) : glossy.eval(wi, wo);
      EXPECT_NEAR(fb.x, (f.x - fg.x) * term(wo) + fg.x, 1e-5f * (1 + f.x));
      EXPECT_FLOAT_EQ(pdf_bumped, pdf_plain);
      scaled += term(wo) < 1.0f;
      const BsdfSample s = bumped.sample(wi, rng.uniform(), Vec2f(rng.uniform(), rng.uniform()));
      if (!s.valid) continue;
      float pdf;
      const Spectrum e = bumped.eval_pdf(wi, s.wo, pdf);
      EXPECT_NEAR(s.value.x, e.x, 1e-4f * (1 + e.x));
      EXPECT_NEAR(s.pdf, pdf, 1e-4f * (1 + pdf));
    }
    EXPECT_GT(scaled, 50);
  }
}

// The terminator shading offset (set_terminator_shift, k = 4/3: Cycles' Shading Offset 0.5) scales
// every lobe's value towards a direction above the normal by max(cos(k a), 0) / cos(a), glossy as
// diffuse, and no density; directions past a = 67.5 degrees get nothing; a mirror's sampled
// value too; sampling returns the same values as evaluation.
TEST(ClosureSet, TerminatorShiftScalesEveryLobeAboveTheNormal) {
  const float k = 4.0f / 3.0f;
  auto factor = [&](Vec3f wo) {
    return wo.z > 0.0f ? std::max(std::cos(std::acos(std::min(wo.z, 1.0f)) * k), 0.0f) / wo.z
                       : 1.0f;
  };
  for (const bool single : {true, false}) {
    const ClosureSet plain =
        single ? set_of({lambert(Spectrum(0.7f))}) : set_of({lambert(Spectrum(0.7f)), ggx(0.3f)});
    ClosureSet shifted = plain;
    shifted.set_terminator_shift(k);
    Pcg32 rng(5);
    int zeroed = 0;
    for (int i = 0; i < 500; ++i) {
      const Vec3f wi = incident(0.2f + 0.8f * rng.uniform());
      const Vec3f wo = direction(rng.uniform(), 2 * M_PI * rng.uniform());
      float pdf_plain, pdf_shifted;
      const Spectrum f = plain.eval_pdf(wi, wo, pdf_plain);
      const Spectrum fs = shifted.eval_pdf(wi, wo, pdf_shifted);
      EXPECT_NEAR(fs.x, f.x * factor(wo), 1e-5f * (1 + f.x));
      EXPECT_FLOAT_EQ(pdf_shifted, pdf_plain);
      zeroed += f.x > 0.0f && fs.x == 0.0f;
      const BsdfSample s = shifted.sample(wi, rng.uniform(), Vec2f(rng.uniform(), rng.uniform()));
      if (!s.valid) continue;
      float pdf;
      const Spectrum e = shifted.eval_pdf(wi, s.wo, pdf);
      EXPECT_NEAR(s.value.x, e.x, 1e-4f * (1 + e.x));
      EXPECT_NEAR(s.pdf, pdf, 1e-4f * (1 + pdf));
    }
    EXPECT_GT(zeroed, 50);  // cos(a) < cos(67.5 degrees) = 0.383: about 38% of wo
  }
  // A mirror: the sampled (delta) value and the delta event take the factor at the reflection.
  const Vec3f wi = incident(0.6f);
  ClosureSet mirror = set_of({ggx(0.0f)});
  const BsdfSample m = mirror.sample(wi, 0.5f, Vec2f(0.5f, 0.5f));
  mirror.set_terminator_shift(k);
  const BsdfSample ms = mirror.sample(wi, 0.5f, Vec2f(0.5f, 0.5f));
  ASSERT_TRUE(m.valid && ms.valid && m.is_delta());
  EXPECT_NEAR(ms.value.y, m.value.y * factor(m.wo), 1e-5f * m.value.y);
  EXPECT_NEAR(mirror.delta_event(wi, kLobeReflection).value.y, ms.value.y, 1e-5f * m.value.y);
  // k <= 1 (no offset) leaves the set on its fast path, untouched.
  ClosureSet off = set_of({lambert(Spectrum(0.7f))});
  off.set_terminator_shift(1.0f);
  const Vec3f wo = direction(0.3f, 1.0f);
  EXPECT_EQ(off.eval(wi, wo).x, set_of({lambert(Spectrum(0.7f))}).eval(wi, wo).x);
}

// A lobe about its own normal n (ClosureSet::set_interpolated_normal) is the same lobe seen in a
// rotated frame: for isotropic lobes any rotation taking n to +z gives the same value and
// density. The rotation here is built independently of Frame (Rodrigues' formula, then a turn
// about z), and a diffuse lobe about its own normal is not bump-shadowed (its normal is the
// interpolated one).
TEST(ClosureSet, LobeAboutItsOwnNormalIsTheRotatedLobe) {
  const Vec3f n = normalize(Vec3f(0.5f, -0.3f, 0.8f));
  // Rodrigues: rotate n onto z about axis n x z, then by 0.7 rad about z.
  const Vec3f axis = normalize(cross(n, Vec3f(0, 0, 1)));
  const float angle = std::acos(n.z);
  auto rotate = [&](Vec3f v) {
    const float c = std::cos(angle), s = std::sin(angle);
    const Vec3f r = v * c + cross(axis, v) * s + axis * (dot(axis, v) * (1 - c));
    const float c2 = std::cos(0.7f), s2 = std::sin(0.7f);
    return Vec3f(c2 * r.x - s2 * r.y, s2 * r.x + c2 * r.y, r.z);
  };
  EXPECT_NEAR(rotate(n).z, 1.0f, 1e-6f);
  for (const Closure& lobe : {ggx(0.3f), ggx_principled(0.1f, 1.5f, Spectrum(0.04f)),
                              principled_diffuse(0.4f), lambert()}) {
    // Geometric normal n too: every direction is then on the lobe's side of the surface.
    ClosureSet own;
    own.add(kept(lobe));
    own.set_interpolated_normal(n, n);
    own.set_bump_shadowing(normalize(Vec3f(0.2f, 0.1f, 1.0f)));  // must not touch it
    const ClosureSet plain = set_of({lobe});
    Pcg32 rng(11);
    int nonzero = 0;
    for (int i = 0; i < 300; ++i) {
      const Vec3f wi = direction(0.1 + 0.9 * rng.uniform(), 2 * M_PI * rng.uniform());
      const Vec3f wo = direction(-0.3 + 1.3 * rng.uniform(), 2 * M_PI * rng.uniform());
      if (!(dot(wi, n) > 0.0f))
        continue;  // wi must face the lobe, as the reflection check makes it
      float p_own, p_plain;
      const Spectrum f_own = own.eval_pdf(wi, wo, p_own);
      const Spectrum f_plain = plain.eval_pdf(rotate(wi), rotate(wo), p_plain);
      EXPECT_NEAR(f_own.y, f_plain.y, 2e-5f * (1 + f_plain.y)) << int(lobe.type);
      EXPECT_NEAR(p_own, p_plain, 2e-5f * (1 + p_plain)) << int(lobe.type);
      nonzero += f_plain.y > 0.0f;
      const BsdfSample s = own.sample(wi, 0.5f, Vec2f(rng.uniform(), rng.uniform()));
      if (s.valid) {
        EXPECT_GT(dot(s.wo, n) * dot(wi, n), 0.0f) << "sampled about n";
      }
    }
    EXPECT_GT(nonzero, 100);
  }
}

// Anisotropic GGX of equal widths is GGX, and its white furnace loses no more than GGX's of the
// wider width (single scattering: the narrow direction loses less).
TEST(AnisotropicGgx, EqualWidthsAreTheIsotropicLobe) {
  Pcg32 rng(21);
  for (float a : {0.05f, 0.3f, 0.9f}) {
    const ClosureSet iso = set_of({ggx(a)}), aniso = set_of({aniso_ggx(a, a, 0.8f)});
    for (int i = 0; i < 200; ++i) {
      const Vec3f wi = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
      const Vec3f wo = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
      float pi, pa;
      const float fi = iso.eval_pdf(wi, wo, pi).y, fa = aniso.eval_pdf(wi, wo, pa).y;
      EXPECT_NEAR(fa, fi, 1e-4f * std::max(1.0f, fi)) << a;
      EXPECT_NEAR(pa, pi, 1e-4f * std::max(1.0f, pi)) << a;
    }
  }
  const Vec3f wi = incident(0.8f);
  const double wide = albedo_quadrature(set_of({ggx(0.6f)}), wi);
  const double mixed = albedo_quadrature(set_of({aniso_ggx(0.05f, 0.6f, 0.3f)}), wi);
  EXPECT_GT(mixed, wide);
  EXPECT_LE(mixed, 1.0 + 1e-3);
}

// Rotating the tangent by 90 degrees swaps the widths: (ax, ay) at angle t + pi/2 is (ay, ax) at
// t, for values, densities and samples.
TEST(AnisotropicGgx, QuarterTurnSwapsTheWidths) {
  const float t = 0.4f;
  const ClosureSet turned = set_of({aniso_ggx(0.1f, 0.5f, t + 0.5f * float(M_PI))});
  const ClosureSet swapped = set_of({aniso_ggx(0.5f, 0.1f, t)});
  const ClosureSet unswapped = set_of({aniso_ggx(0.1f, 0.5f, t)});
  Pcg32 rng(8);
  double differs = 0.0;
  for (int i = 0; i < 300; ++i) {
    const Vec3f wi = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
    const Vec3f wo = direction(0.05 + 0.95 * rng.uniform(), 2 * M_PI * rng.uniform());
    float p_t, p_s;
    const float f_t = turned.eval_pdf(wi, wo, p_t).y, f_s = swapped.eval_pdf(wi, wo, p_s).y;
    EXPECT_NEAR(f_t, f_s, 1e-4f * std::max(1.0f, f_s));
    EXPECT_NEAR(p_t, p_s, 1e-4f * std::max(1.0f, p_s));
    differs += std::fabs(unswapped.eval(wi, wo).y - f_s);
    const Vec2f u(rng.uniform(), rng.uniform());
    const BsdfSample a = turned.sample(wi, 0.5f, u), b = swapped.sample(wi, 0.5f, u);
    ASSERT_EQ(a.valid, b.valid);
    if (a.valid) {
      EXPECT_NEAR(a.wo.x, b.wo.x, 1e-4f);
      EXPECT_NEAR(a.wo.y, b.wo.y, 1e-4f);
      EXPECT_NEAR(a.wo.z, b.wo.z, 1e-4f);
    }
  }
  EXPECT_GT(differs, 1.0) << "the widths matter: unrotated (ax, ay) is another lobe";
}

// Degenerate inputs: zero roughness, exactly grazing wi (z = 0), wo = -wi, wo = wi, poles.
// Two anisotropic lobes with their own tangents: orient_own_tangents turns the second by the
// angle from the frame's x axis (the first's tangent) to its tangent projected onto the tangent
// plane, so the set evaluates as if that lobe had been rotated there; a second call changes
// nothing, and a set whose lobes share a tangent is left alone.
TEST(AnisotropicGgx, OwnTangentsTurnEachLobe) {
  Closure a = aniso_ggx(0.05f, 0.4f), b = aniso_ggx(0.02f, 0.3f, 0.5f);
  a.tangent = Vec3f(1.0f, 0.0f, 0.0f);
  // 60 degrees from x in the tangent plane, tilted out of it (the projection counts).
  b.tangent = Vec3f(0.5f, 0.8660254f, 0.7f);
  ClosureSet set = set_of({a, b});
  EXPECT_TRUE(set.has_own_tangents());
  const Frame frame;  // x along a's tangent, normal +z
  set.orient_own_tangents(frame);
  EXPECT_FALSE(set.has_own_tangents());
  Closure turned = b;
  const float angle = 0.5f + float(M_PI) / 3.0f;
  turned.rotation = Vec2f(std::cos(angle), std::sin(angle));
  EXPECT_NEAR(set[1].rotation.x, turned.rotation.x, 1e-5f);
  EXPECT_NEAR(set[1].rotation.y, turned.rotation.y, 1e-5f);
  const ClosureSet expected = set_of({a, turned});
  ClosureSet again = set;
  again.orient_own_tangents(Frame(Vec3f(0, 1, 0), Vec3f(-1, 0, 0), Vec3f(0, 0, 1)));
  Pcg32 rng(3);
  for (int i = 0; i < 200; ++i) {
    const Vec3f wi = direction(0.1 + 0.9 * rng.uniform(), 2 * M_PI * rng.uniform());
    const Vec3f wo = direction(0.1 + 0.9 * rng.uniform(), 2 * M_PI * rng.uniform());
    const float e = expected.eval(wi, wo).y;
    EXPECT_NEAR(set.eval(wi, wo).y, e, 1e-4f * e + 1e-6f);
    EXPECT_EQ(again.eval(wi, wo).y, set.eval(wi, wo).y);
  }
  // The same tangent: not turned.
  b.tangent = a.tangent;
  ClosureSet shared = set_of({a, b});
  EXPECT_FALSE(shared.has_own_tangents());
  shared.orient_own_tangents(Frame(Vec3f(0, 1, 0), Vec3f(-1, 0, 0), Vec3f(0, 0, 1)));
  EXPECT_EQ(shared[1].rotation.x, b.rotation.x);
}

TEST(BsdfRobustness, NoNaNOrInfInDegenerateConfigurations) {
  std::vector<Closure> lobes = {lambert(), oren_nayar(1.0f), principled_diffuse(1.0f),
                                principled_sheen(), transparent()};
  for (float a : {0.0f, 1e-6f, 1e-4f, 3.2e-4f, 1e-3f, 1.0f}) {
    lobes.push_back(ggx(a));
    lobes.push_back(ggx_principled(a, 1.5f, Spectrum(0.5f)));
    lobes.push_back(glass(a, 1.5f));
    lobes.push_back(glass(a, 1.00001f));
    lobes.push_back(beckmann(ggx(a)));
    lobes.push_back(beckmann(glass(a, 1.5f)));
    lobes.push_back(beckmann(refraction(a, 1.5f)));
    lobes.push_back(ashikhmin_shirley(ggx(a)));
    lobes.push_back(ashikhmin_shirley(aniso_ggx(a, 0.3f)));
    lobes.push_back(clearcoat(a));
    lobes.push_back(kept(clearcoat(a)));
  }
  const Vec3f wis[] = {Vec3f(1, 0, 0),  Vec3f(0, 0, 1),   Vec3f(0, 0, -1),
                       incident(1e-7f), incident(-1e-7f), normalize(Vec3f(1, 1, 0))};
  for (const Closure& c : lobes) {
    // A kept lobe is evaluated about a tilted normal.
    const ClosureSet set = set_of({c, lambert(Spectrum(0.1f))}, Vec3f(0.3f, 0.2f, 0.9f));
    for (const Vec3f& wi : wis) {
      const Vec3f wos[] = {
          -wi, wi, Vec3f(0, 0, 1), Vec3f(0, 0, -1), Vec3f(1, 0, 0), Vec3f(-wi.x, -wi.y, wi.z)};
      for (const Vec3f& wo : wos) {
        EXPECT_TRUE(is_finite(set.eval(wi, wo))) << int(c.type) << " alpha " << c.alpha;
        EXPECT_TRUE(std::isfinite(set.pdf(wi, wo))) << int(c.type) << " alpha " << c.alpha;
      }
      for (float u : {0.0f, 0.5f, 0.99999994f}) {
        const BsdfSample s = set.sample(wi, u, Vec2f(u, 1.0f - u));
        if (!s.valid) continue;
        EXPECT_TRUE(is_finite(s.value) && std::isfinite(s.pdf) && is_finite(s.wo))
            << int(c.type) << " alpha " << c.alpha;
        EXPECT_TRUE(is_finite(s.weight()));
      }
    }
  }
}

}  // namespace
}  // namespace gdpt::test
