// GGX microfacet reflection, two-sided, as Cycles 3.4's `microfacet_ggx` (Glossy BSDF) and
// `microfacet_ggx_fresnel` (Principled v1 specular):
//   f |cos_o| = weight * F(wo.h) * D(h) G1(wi) G1(wo) / (4 cos_i),   h = normalize(wi + wo)
// F = 1 for FresnelMode::None (the Glossy colour simply scales), and Cycles' Principled v1 blend
// PrincipledFresnel(Closure::ior, Closure::f0) for FresnelMode::PrincipledV1.
// Sampling: visible normals from wi, so value / pdf = F G1(wo).
// alpha < kDeltaAlpha: a perfect mirror (delta), value = weight F(cos_i), pdf = 1.
#pragma once

#include "shaders/closure.h"
#include "shaders/fresnel.h"
#include "shaders/lobe_util.h"
#include "shaders/microfacet.h"

namespace gdpt::ggx_reflection {

inline Spectrum fresnel(const Closure& c, float cos_h) {
  if (c.fresnel != FresnelMode::PrincipledV1) return Spectrum(1.0f);
  return PrincipledFresnel(c.ior, c.f0)(cos_h);
}

// wi, wo already mirrored to wi.z > 0. Returns eval, writes the pdf.
inline Spectrum eval_pdf_upper(const Closure& c, Vec3f wi, Vec3f wo, float& pdf) {
  pdf = 0.0f;
  if (!(wi.z > 0.0f && wo.z > 0.0f)) return Spectrum(0.0f);
  const Vec3f sum = wi + wo;
  const float len2 = length_squared(sum);
  if (!(len2 > 0.0f)) return Spectrum(0.0f);
  const Vec3f h = sum / std::sqrt(len2);
  const GGX ggx(c.alpha);
  const float d = ggx.D(h);
  const float g1i = ggx.G1(wi);
  const float common = d * g1i / (4.0f * wi.z);
  pdf = common;
  return c.weight * fresnel(c, dot(wo, h)) * (common * ggx.G1(wo));
}

inline Spectrum eval(const Closure& c, Vec3f wi, Vec3f wo) {
  if (is_delta_alpha(c.alpha) || !(wi.z * wo.z > 0.0f)) return Spectrum(0.0f);
  const MirroredPair p(wi, wo);
  float pdf;
  return eval_pdf_upper(c, p.wi, p.wo, pdf);
}

inline float pdf(const Closure& c, Vec3f wi, Vec3f wo) {
  if (is_delta_alpha(c.alpha) || !(wi.z * wo.z > 0.0f)) return 0.0f;
  // Density only: D(h) G1(wi) / (4 cos_i), without the Fresnel and G1(wo) of the value.
  const MirroredPair p(wi, wo);
  const Vec3f sum = p.wi + p.wo;
  const float len2 = length_squared(sum);
  if (!(len2 > 0.0f)) return 0.0f;
  const GGX ggx(c.alpha);
  return ggx.D(sum / std::sqrt(len2)) * ggx.G1(p.wi) / (4.0f * p.wi.z);
}

inline BsdfSample sample(const Closure& c, Vec3f wi_, float, Vec2f u) {
  BsdfSample s;
  if (wi_.z == 0.0f) return s;
  const float sign = wi_.z < 0.0f ? -1.0f : 1.0f;
  const Vec3f wi = flip_z(wi_, sign);
  s.eta = 1.0f;
  if (is_delta_alpha(c.alpha)) {
    s.wo = flip_z(Vec3f(-wi.x, -wi.y, wi.z), sign);
    s.value = c.weight * fresnel(c, wi.z);
    s.pdf = 1.0f;
    s.roughness = 0.0f;
    s.lobe = kLobeReflection | kLobeDelta;
    s.valid = true;
    return s;
  }
  const GGX ggx(c.alpha);
  const Vec3f m = ggx.sample_visible(wi, u);
  const Vec3f wo = reflect(wi, m);
  if (wo.z <= 0.0f) return s;
  s.value = eval_pdf_upper(c, wi, wo, s.pdf);
  if (!(s.pdf > 0.0f)) return s;
  s.wo = flip_z(wo, sign);
  s.roughness = c.alpha;
  s.lobe = kLobeReflection | kLobeGlossy;
  s.valid = true;
  return s;
}

// Cycles weights Principled specular selection by the Fresnel colour at the shading normal.
inline float albedo_hint(const Closure& c, Vec3f wi) {
  if (c.fresnel != FresnelMode::PrincipledV1) return 1.0f;
  return selection_luminance(fresnel(c, std::fabs(wi.z)));
}

}  // namespace gdpt::ggx_reflection
