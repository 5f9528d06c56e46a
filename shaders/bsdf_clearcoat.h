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

#include <algorithm>
#include <cmath>

#include "shaders/closure.h"
#include "shaders/fresnel.h"
#include "shaders/lobe_util.h"
#include "shaders/microfacet.h"
#include "shaders/reflection_lobe.h"

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
  Vec3f h;
  if (!reflection_lobe::upper_half_vector(wi, wo, h)) return Spectrum(0.0f);
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
  return reflection_lobe::eval(c, wi, wo, eval_pdf_upper);
}

inline float pdf(const Closure& c, Vec3f wi, Vec3f wo) {
  return reflection_lobe::pdf(c, wi, wo, [](const Closure& k, Vec3f, Vec3f o, Vec3f h) {
    const float cos_oh = dot(o, h);
    if (!(cos_oh > 0.0f) || !(h.z > 0.0f)) return 0.0f;
    return gtr1(k.alpha * k.alpha, h.z) * h.z / (4.0f * cos_oh);
  });
}

// Half vectors from D(h) cos theta_h (the alpha -> 1 limit is cos^2 = 1 - u).
inline Vec3f sample_normal(const Closure& c, Vec3f, Vec2f u) {
  const float a2 = c.alpha * c.alpha;
  const float cos2 = a2 < 1.0f ? (1.0f - std::pow(a2, 1.0f - u.x)) / (1.0f - a2) : 1.0f - u.x;
  const float cos_h = std::sqrt(std::clamp(cos2, 0.0f, 1.0f));
  const float sin_h = std::sqrt(std::max(0.0f, 1.0f - cos_h * cos_h));
  const float phi = 2.0f * kPi * u.y;
  return Vec3f(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
}

inline BsdfSample sample(const Closure& c, Vec3f wi, float, Vec2f u) {
  return reflection_lobe::sample(
      c, wi, u,
      [](const Closure& k, float cos_i) { return k.weight * fresnel_dielectric(cos_i, kIor); },
      sample_normal, eval_pdf_upper);
}

// Cycles weights the clearcoat's selection by its Fresnel at the shading normal.
inline float albedo_hint(const Closure&, Vec3f wi) {
  return fresnel_dielectric(std::fabs(wi.z), kIor);
}

}  // namespace gdpt::clearcoat
