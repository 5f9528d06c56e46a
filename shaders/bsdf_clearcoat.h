// Principled v1 clearcoat, as Cycles 3.4 evaluates it (CLOSURE_BSDF_MICROFACET_GGX_CLEARCOAT_ID,
// after Burley 2012): a two-sided reflection lobe
//   f |cos_o| = weight * F(wo.h) * D(h) G1(wi) G1(wo) / (4 cos_i),   h = normalize(wi + wo)
// with Burley's GTR1 distribution ("Generalized Trowbridge-Reitz", gamma = 1, a long-tailed
// highlight) of width alpha = clearcoat_roughness^2,
//   D(h) = (alpha^2 - 1) / (pi ln(alpha^2) (1 + (alpha^2 - 1) cos^2 theta_h))   (1 / pi at alpha
//   1),
// GGX Smith masking of a fixed alpha of 0.25 for both directions, and the dielectric Fresnel of
// IOR 1.5 (Cycles' Fresnel blend of cspec0 = 0.04 towards white reduces to it exactly).
// The weight carries Cycles' 0.25 * clearcoat.
//
// Sampling: h from D(h) cos theta_h exactly (Burley's inversion,
// cos^2 theta_h = (1 - alpha^2^(1 - u)) / (1 - alpha^2)), wo = reflect(wi, h), density
// D(h) cos theta_h / (4 wo.h). (Cycles 3.4 samples the GGX visible normals of alpha instead and
// reports the density G1(wi) D(h) / (4 cos_i) of the lobe above, which is not the density it
// samples: its BSDF-sampled clearcoat is slightly off its own evaluation. Here sampling and
// density agree, so the estimate converges to the lobe above.)
// alpha < kDeltaAlpha: a perfect mirror, value = weight F(cos_i), as Cycles.
#pragma once

#include <cmath>

#include "shaders/closure.h"
#include "shaders/fresnel.h"
#include "shaders/lobe_util.h"
#include "shaders/microfacet.h"

namespace gdpt::clearcoat {

inline constexpr float kIor = 1.5f;
inline constexpr float kMaskingAlpha = 0.25f;

// GTR1 D of cos theta_h for alpha^2 = a2 < 1.
inline float gtr1(float a2, float cos_h) {
  if (a2 >= 1.0f) return 1.0f / kPi;
  const float t = 1.0f + (a2 - 1.0f) * cos_h * cos_h;
  return (a2 - 1.0f) / (kPi * std::log(a2) * t);
}

// wi, wo already mirrored to wi.z > 0. Returns eval, writes the pdf.
inline Spectrum eval_pdf_upper(const Closure& c, Vec3f wi, Vec3f wo, float& pdf) {
  pdf = 0.0f;
  if (!(wi.z > 0.0f && wo.z > 0.0f)) return Spectrum(0.0f);
  const Vec3f sum = wi + wo;
  const float len2 = length_squared(sum);
  if (!(len2 > 0.0f)) return Spectrum(0.0f);
  const Vec3f h = sum / std::sqrt(len2);
  const float cos_oh = dot(wo, h);
  if (!(cos_oh > 0.0f)) return Spectrum(0.0f);
  const float d = gtr1(c.alpha * c.alpha, h.z);
  pdf = d * h.z / (4.0f * cos_oh);
  const GGX masking(kMaskingAlpha);
  const float value =
      fresnel_dielectric(cos_oh, kIor) * d * masking.G1(wi) * masking.G1(wo) / (4.0f * wi.z);
  return c.weight * value;
}

inline Spectrum eval(const Closure& c, Vec3f wi, Vec3f wo) {
  if (is_delta_alpha(c.alpha) || !(wi.z * wo.z > 0.0f)) return Spectrum(0.0f);
  const MirroredPair p(wi, wo);
  float pdf;
  return eval_pdf_upper(c, p.wi, p.wo, pdf);
}

inline float pdf(const Closure& c, Vec3f wi, Vec3f wo) {
  if (is_delta_alpha(c.alpha) || !(wi.z * wo.z > 0.0f)) return 0.0f;
  const MirroredPair p(wi, wo);
  const Vec3f sum = p.wi + p.wo;
  const float len2 = length_squared(sum);
  if (!(len2 > 0.0f)) return 0.0f;
  const Vec3f h = sum / std::sqrt(len2);
  const float cos_oh = dot(p.wo, h);
  if (!(cos_oh > 0.0f) || !(h.z > 0.0f)) return 0.0f;
  return gtr1(c.alpha * c.alpha, h.z) * h.z / (4.0f * cos_oh);
}

inline BsdfSample sample(const Closure& c, Vec3f wi_, float, Vec2f u) {
  BsdfSample s;
  if (wi_.z == 0.0f) return s;
  const float sign = wi_.z < 0.0f ? -1.0f : 1.0f;
  const Vec3f wi = flip_z(wi_, sign);
  s.eta = 1.0f;
  if (is_delta_alpha(c.alpha)) {
    s.wo = flip_z(Vec3f(-wi.x, -wi.y, wi.z), sign);
    s.value = c.weight * fresnel_dielectric(wi.z, kIor);
    s.pdf = 1.0f;
    s.roughness = 0.0f;
    s.lobe = kLobeReflection | kLobeDelta;
    s.valid = true;
    return s;
  }
  // --- Half vector from D(h) cos theta_h (the alpha -> 1 limit is cos^2 = 1 - u).
  const float a2 = c.alpha * c.alpha;
  const float cos2 = a2 < 1.0f ? (1.0f - std::pow(a2, 1.0f - u.x)) / (1.0f - a2) : 1.0f - u.x;
  const float cos_h = std::sqrt(std::clamp(cos2, 0.0f, 1.0f));
  const float sin_h = std::sqrt(std::max(0.0f, 1.0f - cos_h * cos_h));
  const float phi = 2.0f * kPi * u.y;
  const Vec3f h(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
  const Vec3f wo = reflect(wi, h);
  if (wo.z <= 0.0f) return s;
  s.value = eval_pdf_upper(c, wi, wo, s.pdf);
  if (!(s.pdf > 0.0f)) return s;
  s.wo = flip_z(wo, sign);
  s.roughness = c.alpha;
  s.lobe = kLobeReflection | kLobeGlossy;
  s.valid = true;
  return s;
}

// Cycles weights the clearcoat's selection by its Fresnel at the shading normal.
inline float albedo_hint(const Closure&, Vec3f wi) {
  return fresnel_dielectric(std::fabs(wi.z), kIor);
}

}  // namespace gdpt::clearcoat
