// Microfacet dielectric (Blender Glass and Refraction BSDFs, GGX or Beckmann by
// Closure::distribution; Principled v1 transmission, GGX), as Cycles 3.4.
//
// Side: Closure::ior is the IOR below the frame normal relative to above it. wi.z > 0: the ray
// crosses with eta = n_t / n_i = ior; wi.z < 0: with eta = 1 / ior. The integrators orient the
// frame towards the incoming ray (as Cycles flips N on back faces) and Material stores 1 / ior
// for back-face hits, so entering and leaving an object both come out right; a frame left on
// the geometric side with front_facing = true works as well. The problem is mirrored so that
// wi.z > 0 internally.
//
// Cycles 3.4 builds the Glass BSDF from two closures split by the Fresnel term at the SHADING
// normal, F = fresnel_dielectric(cos_i, eta) (not per microfacet), and so do we:
//   reflection   (wo.z > 0):  R(h) F D(h) G1(wi) G1(wo) / (4 cos_i),   h = normalize(wi + wo)
//   transmission (wo.z < 0):  T (1 - F) D(h) G1(wi) G1(wo) eta^2 |wi.h| |wo.h|
//                                          / (cos_i (wi.h + eta wo.h)^2), h ~ -(wi + eta wo)
// with R(h) = weight (Glass) or weight * PrincipledFresnel(ior, f0)(wo.h) (Principled), and
// T = weight * transmission_tint. The density replaces G1(wi) G1(wo) by G1_visible(wi) (the
// visible-normal sampler's, microfacet.h).
// Radiance scaling: the transmitted part carries eta^2 relative to Walter et al.'s radiance
// BTDF, i.e. radiance is NOT scaled by 1/eta^2 when it crosses the interface. This is what Cycles
// does (bsdf_microfacet_ggx_eval_transmit multiplies by m_eta^2; the sharp refraction closure
// returns weight 1): a camera path entering glass keeps throughput (1 - F), not (1 - F) / eta^2.
// Consequence: f(wi, wo) = eta^2 f(wo, wi) for the microfacet part (tested).
// A refraction sampled through a microfacet that totally reflects internally is lost (invalid
// sample), as in Cycles.
// Smooth (alpha < kDeltaAlpha) or eta ~ 1: delta lobes; reflection is chosen with probability
// P_R (Fresnel weighted by colour luminances), value = R F, transmission value = T (1 - F).
// FresnelMode::RefractionOnly (Refraction BSDF): F = 0 throughout, so no reflection and the
// transmission is T D G ... without (1 - F); total internal reflection still loses the sample.
// drop_reflection / drop_refraction (Cycles' caustics toggles, one of the two closures left out):
// the dropped part evaluates to 0 and is never sampled; the other keeps its F or (1 - F).
// Closure::multiscatter (Blender's Multiscatter GGX glass): the rough lobe takes the single-
// scattering term of Cycles' random walk on the microsurface, which splits by the Fresnel term of
// the MICROFACET, F(wi.h) (so light also leaves past the critical angle of the shading normal,
// through tilted microfacets; sampled with that split), and its value is multiplied by
//   1 + multiscatter_tint (1 / E(cos_i) - 1),
// E that white lobe's directional albedo from wi's side (ggx_dielectric_albedo.h), so that a
// white lobe reflects and refracts all the light from every direction, as the random walk does;
// the shape and the density stay the single-scattering lobe's. Everything is a function of wi,
// wo, alpha and eta: a shifted path evaluates it for its own directions.
#pragma once

#include "shaders/closure.h"
#include "shaders/fresnel.h"
#include "shaders/ggx_dielectric_albedo.h"
#include "shaders/lobe_util.h"
#include "shaders/microfacet.h"

namespace gdpt::ggx_dielectric {

// Per-call set-up from wi (mirrored to wi.z > 0): relative IOR, Fresnel split, selection.
struct Setup {
  float eta;      // n_t / n_i
  float fresnel;  // reflectance at the shading normal
  float p_reflect;
  bool smooth;                              // delta reflection and refraction
  bool pass_through;                        // eta ~ 1: refraction is a straight delta pass-through
  Spectrum compensation{1.0f, 1.0f, 1.0f};  // Closure::multiscatter's factor on the rough lobe
};

inline Spectrum reflection_colour(const Closure& c, float eta, float cos_h) {
  if (c.fresnel != FresnelMode::PrincipledV1) return c.weight;
  return c.weight * PrincipledFresnel(eta, c.f0)(cos_h);
}

// The Fresnel split at a normal of cosine `cos` with wi: reflectance and the probability of
// sampling the reflection (Fresnel weighted by colour luminances).
struct Split {
  float fresnel;
  float p_reflect;
};

inline Split split(const Closure& c, float eta, float cos) {
  Split s;
  s.fresnel = c.fresnel == FresnelMode::RefractionOnly ? 0.0f : fresnel_dielectric(cos, eta);
  const float r =
      c.drop_reflection ? 0.0f : s.fresnel * selection_luminance(reflection_colour(c, eta, cos));
  const float t = c.drop_refraction
                      ? 0.0f
                      : (1.0f - s.fresnel) * selection_luminance(c.weight * c.transmission_tint);
  const float fallback = c.drop_reflection ? 0.0f : c.drop_refraction ? 1.0f : s.fresnel;
  s.p_reflect = (r + t) > 0.0f ? r / (r + t) : fallback;
  return s;
}

// `compensate` false: the single-scattering lobe (what ggx_dielectric_albedo tabulates).
inline Setup setup(const Closure& c, float cos_i, bool entering, bool compensate = true) {
  Setup s;
  const float ior = std::max(c.ior, 1e-5f);
  s.eta = entering ? ior : 1.0f / ior;
  const Split sp = split(c, s.eta, cos_i);
  s.fresnel = sp.fresnel;
  s.p_reflect = sp.p_reflect;
  s.smooth = is_delta_alpha(c.alpha);
  s.pass_through = std::fabs(s.eta - 1.0f) < 1e-4f;
  if (compensate && c.multiscatter && !s.smooth && !s.pass_through) {
    const float e = ggx_dielectric_albedo(cos_i, c.alpha, s.eta);
    if (e > 1e-4f) s.compensation = Spectrum(1.0f) + c.multiscatter_tint * (1.0f / e - 1.0f);
  }
  return s;
}

// The split of the rough lobe at microfacet normal h: the shading normal's, or (multiscatter)
// the microfacet's own.
inline Split rough_split(const Closure& c, const Setup& st, Vec3f wi, Vec3f h) {
  if (!c.multiscatter) return {st.fresnel, st.p_reflect};
  return split(c, st.eta, dot(wi, h));
}

// Non-delta part; wi, wo mirrored so that wi.z > 0. Returns eval, writes the pdf.
inline Spectrum eval_pdf_upper(const Closure& c, const Setup& st, Vec3f wi, Vec3f wo, float& pdf) {
  pdf = 0.0f;
  if (st.smooth || !(wi.z > 0.0f) || wo.z == 0.0f) return Spectrum(0.0f);
  const Microfacet mf(c.distribution, c.alpha);
  if (wo.z > 0.0f) {
    const Vec3f sum = wi + wo;
    const float len2 = length_squared(sum);
    if (!(len2 > 0.0f) || c.drop_reflection) return Spectrum(0.0f);
    const Vec3f h = sum / std::sqrt(len2);
    const Split sp = rough_split(c, st, wi, h);
    if (sp.fresnel <= 0.0f) return Spectrum(0.0f);
    const float common = mf.D(h) / (4.0f * wi.z);
    pdf = sp.p_reflect * common * mf.G1_visible(wi);
    return reflection_colour(c, st.eta, dot(wo, h)) * st.compensation *
           (sp.fresnel * common * mf.G1(wi) * mf.G1(wo));
  }
  if (st.pass_through || c.drop_refraction) return Spectrum(0.0f);
  // Generalised half vector of the refraction, oriented to the outside (+z).
  Vec3f ht = wi + wo * st.eta;
  const float len2 = length_squared(ht);
  if (!(len2 > 0.0f)) return Spectrum(0.0f);
  ht = ht / std::sqrt(len2);
  if (ht.z < 0.0f) ht = -ht;
  const float cos_ih = dot(wi, ht), cos_oh = dot(wo, ht);
  // Only microfacets facing wi that refract towards wo contribute.
  if (!(cos_ih > 0.0f && cos_oh < 0.0f)) return Spectrum(0.0f);
  const Split sp = rough_split(c, st, wi, ht);
  if (sp.fresnel >= 1.0f) return Spectrum(0.0f);
  const float denom = cos_ih + st.eta * cos_oh;
  const float jacobian = st.eta * st.eta * std::fabs(cos_oh) / (denom * denom);  // dwh / dwo
  const float common = cos_ih * mf.D(ht) / wi.z * jacobian;
  pdf = (1.0f - sp.p_reflect) * common * mf.G1_visible(wi);
  return c.weight * c.transmission_tint * st.compensation *
         ((1.0f - sp.fresnel) * common * mf.G1(wi) * mf.G1(wo));
}

inline Spectrum eval(const Closure& c, Vec3f wi, Vec3f wo) {
  if (wi.z == 0.0f) return Spectrum(0.0f);
  const MirroredPair p(wi, wo);
  const Setup st = setup(c, p.wi.z, wi.z > 0.0f);
  float pdf;
  return eval_pdf_upper(c, st, p.wi, p.wo, pdf);
}

inline float pdf(const Closure& c, Vec3f wi, Vec3f wo) {
  if (wi.z == 0.0f) return 0.0f;
  const MirroredPair p(wi, wo);
  const Setup st = setup(c, p.wi.z, wi.z > 0.0f);
  float pdf;
  eval_pdf_upper(c, st, p.wi, p.wo, pdf);
  return pdf;
}

inline BsdfSample sample(const Closure& c, Vec3f wi_, float u_choice, Vec2f u) {
  BsdfSample s;
  if (wi_.z == 0.0f) return s;
  const float sign = wi_.z < 0.0f ? -1.0f : 1.0f;
  const Vec3f wi = flip_z(wi_, sign);
  const Setup st = setup(c, wi.z, wi_.z > 0.0f);
  bool pick_reflection = u_choice < st.p_reflect;

  // Delta cases: smooth glass, or the straight pass-through of an index-matched interface.
  if (st.smooth || (!pick_reflection && st.pass_through)) {
    if (pick_reflection) {
      s.wo = flip_z(Vec3f(-wi.x, -wi.y, wi.z), sign);
      s.value = reflection_colour(c, st.eta, wi.z) * st.fresnel;
      s.pdf = st.p_reflect;
      s.eta = 1.0f;
      s.lobe = kLobeReflection | kLobeDelta;
    } else {
      Vec3f wt;
      if (!refract(wi, Vec3f(0.0f, 0.0f, 1.0f), st.eta, wt)) return s;
      s.wo = flip_z(wt, sign);
      s.value = c.weight * c.transmission_tint * (1.0f - st.fresnel);
      s.pdf = 1.0f - st.p_reflect;
      s.eta = st.eta;
      s.lobe = kLobeTransmission | kLobeDelta;
    }
    s.roughness = 0.0f;
    s.valid = s.pdf > 0.0f;
    return s;
  }

  const Vec3f m = Microfacet(c.distribution, c.alpha).sample_visible(wi, u);
  Vec3f wo;
  if (c.multiscatter) pick_reflection = u_choice < rough_split(c, st, wi, m).p_reflect;
  if (pick_reflection) {
    wo = reflect(wi, m);
    if (wo.z <= 0.0f) return s;
    s.eta = 1.0f;
    s.lobe = kLobeReflection | kLobeGlossy;
  } else {
    if (!refract(wi, m, st.eta, wo) || wo.z >= 0.0f) return s;
    s.eta = st.eta;
    s.lobe = kLobeTransmission | kLobeGlossy;
  }
  s.value = eval_pdf_upper(c, st, wi, wo, s.pdf);
  if (!(s.pdf > 0.0f)) return s;
  s.wo = flip_z(wo, sign);
  s.roughness = c.alpha;
  s.valid = true;
  return s;
}

// One quadrature point u of the white single-scattering lobe's directional albedo from wi
// (wi.z > 0, eta = c.ior): both choices at the sampled microfacet, each value over the density of
// its direction given the choice.
inline float single_scattering_albedo_sample(const Closure& c, Vec3f wi, Vec2f u) {
  const Setup st = setup(c, wi.z, true, false);
  const Vec3f m = Microfacet(c.distribution, c.alpha).sample_visible(wi, u);
  const Split sp = rough_split(c, st, wi, m);
  float sum = 0.0f, pdf;
  const Vec3f wr = reflect(wi, m);
  if (wr.z > 0.0f) {
    const Spectrum v = eval_pdf_upper(c, st, wi, wr, pdf);
    if (pdf > 0.0f) sum += v.x / pdf * sp.p_reflect;
  }
  Vec3f wt;
  if (refract(wi, m, st.eta, wt) && wt.z < 0.0f) {
    const Spectrum v = eval_pdf_upper(c, st, wi, wt, pdf);
    if (pdf > 0.0f) sum += v.x / pdf * (1.0f - sp.p_reflect);
  }
  return sum;
}

inline float albedo_hint(const Closure& c, Vec3f wi) {
  if (wi.z == 0.0f) return 0.0f;
  const Setup st = setup(c, std::fabs(wi.z), wi.z > 0.0f);
  const float lw = selection_luminance(c.weight);
  if (!(lw > 0.0f)) return 1.0f;
  const float r =
      c.drop_reflection
          ? 0.0f
          : st.fresnel * selection_luminance(reflection_colour(c, st.eta, std::fabs(wi.z)));
  const float t = c.drop_refraction
                      ? 0.0f
                      : (1.0f - st.fresnel) * selection_luminance(c.weight * c.transmission_tint);
  return (r + t) / lw * selection_luminance(st.compensation);
}

}  // namespace gdpt::ggx_dielectric
