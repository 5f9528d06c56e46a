// Microfacet reflection (GGX, Beckmann or Ashikhmin-Shirley: Closure::distribution; each may be
// anisotropic about the lobe's tangent), two-sided, as Cycles 3.4's
// `microfacet_ggx` / `microfacet_beckmann` / `ashikhmin_shirley` (Glossy and Anisotropic BSDFs)
// and `microfacet_ggx_fresnel` (Principled v1 specular). Ashikhmin-Shirley has its own value,
// density and sampler (shaders/ashikhmin_shirley.h); the others are
//   f |cos_o| = weight * F(wo.h) * D(h) G1(wi) G1(wo) / (4 cos_i),   h = normalize(wi + wo)
// F = 1 for FresnelMode::None (the Glossy colour simply scales), and Cycles' Principled v1 blend
// PrincipledFresnel(Closure::ior, Closure::f0) for FresnelMode::PrincipledV1.
// Sampling: visible normals from wi, pdf = D(h) G1_visible(wi) / (4 cos_i), so value / pdf =
// F G1(wo) for GGX (Beckmann: F G1(wi) G1(wo) / G1_visible(wi), Cycles' fit over the exact term).
// alpha < kDeltaAlpha: a perfect mirror (delta), value = weight F(cos_i), pdf = 1.
#pragma once

#include "shaders/ashikhmin_shirley.h"
#include "shaders/closure.h"
#include "shaders/fresnel.h"
#include "shaders/lobe_util.h"
#include "shaders/microfacet.h"
#include "shaders/reflection_lobe.h"

namespace gdpt::ggx_reflection {

inline Spectrum fresnel(const Closure& c, float cos_h) {
  if (c.fresnel != FresnelMode::PrincipledV1) return Spectrum(1.0f);
  return PrincipledFresnel(c.ior, c.f0)(cos_h);
}

// A direction in the anisotropic lobe's own frame (its tangent on +x), and back.
inline Vec3f to_tangent(const Closure& c, Vec3f w) {
  return {c.rotation.x * w.x + c.rotation.y * w.y, c.rotation.x * w.y - c.rotation.y * w.x, w.z};
}
inline Vec3f from_tangent(const Closure& c, Vec3f w) {
  return {c.rotation.x * w.x - c.rotation.y * w.y, c.rotation.y * w.x + c.rotation.x * w.y, w.z};
}

inline bool is_ashikhmin_shirley(const Closure& c) {
  return c.distribution == MicrofacetDistribution::AshikhminShirley;
}
inline AshikhminShirley ashikhmin_shirley_of(const Closure& c) {
  return AshikhminShirley(c.alpha, is_anisotropic(c) ? c.alpha_y : c.alpha);
}

// Ashikhmin-Shirley in the lobe's frame (the identity rotation when isotropic).
inline Spectrum eval_pdf_as(const Closure& c, Vec3f wi, Vec3f wo, Vec3f h, float& pdf) {
  const float v =
      ashikhmin_shirley_of(c).eval_pdf(to_tangent(c, wi), to_tangent(c, wo), to_tangent(c, h), pdf);
  return c.weight * fresnel(c, dot(wo, h)) * v;
}

inline AnisoMicrofacet aniso_microfacet_of(const Closure& c) {
  return AnisoMicrofacet(c.distribution, c.alpha, c.alpha_y);
}

// The anisotropic lobe: the same formulas with AnisoMicrofacet in the lobe's frame.
inline float pdf_aniso(const Closure& c, Vec3f wi, Vec3f h) {
  const AnisoMicrofacet mf = aniso_microfacet_of(c);
  return mf.D(to_tangent(c, h)) * mf.G1_visible(to_tangent(c, wi)) / (4.0f * wi.z);
}
inline Spectrum eval_pdf_aniso(const Closure& c, Vec3f wi, Vec3f wo, Vec3f h, float& pdf) {
  const AnisoMicrofacet mf = aniso_microfacet_of(c);
  const Vec3f wi_t = to_tangent(c, wi);
  const float common = mf.D(to_tangent(c, h)) / (4.0f * wi.z);
  pdf = common * mf.G1_visible(wi_t);
  return c.weight * fresnel(c, dot(wo, h)) * (common * mf.G1(wi_t) * mf.G1(to_tangent(c, wo)));
}

// wi, wo already mirrored to wi.z > 0. Returns eval, writes the pdf.
inline Spectrum eval_pdf_upper(const Closure& c, Vec3f wi, Vec3f wo, float& pdf) {
  pdf = 0.0f;
  Vec3f h;
  if (!reflection_lobe::upper_half_vector(wi, wo, h)) return Spectrum(0.0f);
  if (is_ashikhmin_shirley(c)) return eval_pdf_as(c, wi, wo, h, pdf);
  if (is_anisotropic(c)) return eval_pdf_aniso(c, wi, wo, h, pdf);
  const Microfacet mf(c.distribution, c.alpha);
  const float common = mf.D(h) / (4.0f * wi.z);
  pdf = common * mf.G1_visible(wi);
  return c.weight * fresnel(c, dot(wo, h)) * (common * mf.G1(wi) * mf.G1(wo));
}

inline Spectrum eval(const Closure& c, Vec3f wi, Vec3f wo) {
  return reflection_lobe::eval(c, wi, wo, eval_pdf_upper);
}

// Density only: D(h) G1_visible(wi) / (4 cos_i), without the Fresnel and masking of the value.
inline float pdf(const Closure& c, Vec3f wi, Vec3f wo) {
  return reflection_lobe::pdf(c, wi, wo, [](const Closure& k, Vec3f i, Vec3f o, Vec3f h) {
    if (is_ashikhmin_shirley(k)) {
      float p;
      ashikhmin_shirley_of(k).eval_pdf(to_tangent(k, i), to_tangent(k, o), to_tangent(k, h), p);
      return p;
    }
    if (is_anisotropic(k)) return pdf_aniso(k, i, h);
    const Microfacet mf(k.distribution, k.alpha);
    return mf.D(h) * mf.G1_visible(i) / (4.0f * i.z);
  });
}

inline BsdfSample sample(const Closure& c, Vec3f wi, float, Vec2f u) {
  return reflection_lobe::sample(
      c, wi, u, [](const Closure& k, float cos_i) { return k.weight * fresnel(k, cos_i); },
      [](const Closure& k, Vec3f i, Vec2f v) {
        if (is_ashikhmin_shirley(k))
          return from_tangent(k, ashikhmin_shirley_of(k).sample_normal(v));
        if (!is_anisotropic(k)) return Microfacet(k.distribution, k.alpha).sample_visible(i, v);
        return from_tangent(k, aniso_microfacet_of(k).sample_visible(to_tangent(k, i), v));
      },
      eval_pdf_upper);
}

// Cycles weights Principled specular selection by the Fresnel colour at the shading normal.
inline float albedo_hint(const Closure& c, Vec3f wi) {
  if (c.fresnel != FresnelMode::PrincipledV1) return 1.0f;
  return selection_luminance(fresnel(c, std::fabs(wi.z)));
}

}  // namespace gdpt::ggx_reflection
