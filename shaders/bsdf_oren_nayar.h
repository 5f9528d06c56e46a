// Oren-Nayar diffuse reflection as Cycles' Diffuse BSDF with roughness > 0 (the "qualitative"
// model of Fujii's improved form): with sigma = clamp(roughness, 0, 1),
//   A = 1 / (pi + (3 pi - 4) / 6 sigma),  B = sigma A,
//   s = dot(wi, wo) - cos_i cos_o,  t = s > 0 ? s / max(cos_i, cos_o) : s,
//   f |cos_o| = weight * cos_o (A + B t).
// Closure::alpha holds sigma. Sampled cosine-weighted (Cycles samples uniformly; the integrand
// is the same, the variance lower).
#pragma once

#include "shaders/closure.h"
#include "shaders/diffuse_sampling.h"
#include "shaders/lobe_util.h"
#include "shaders/sampling.h"

namespace gdpt::oren_nayar {

inline Spectrum eval(const Closure& c, Vec3f wi_, Vec3f wo_) {
  if (!(wi_.z * wo_.z > 0.0f)) return Spectrum(0.0f);
  const MirroredPair p(wi_, wo_);
  const float sigma = std::clamp(c.alpha, 0.0f, 1.0f);
  const float a = 1.0f / (kPi + ((3.0f * kPi - 4.0f) / 6.0f) * sigma);
  const float b = sigma * a;
  const float nl = p.wo.z, nv = p.wi.z;
  float t = dot(p.wi, p.wo) - nl * nv;
  if (t > 0.0f) t /= std::max(nl, nv);
  return c.weight * std::max(0.0f, nl * (a + b * t));
}

inline float pdf(const Closure&, Vec3f wi, Vec3f wo) {
  return cosine_lobe_pdf(wi, wo);
}

inline BsdfSample sample(const Closure& c, Vec3f wi, float, Vec2f u) {
  return sample_cosine_lobe(wi, u, [&](Vec3f wo) { return eval(c, wi, wo); });
}

inline float albedo_hint(const Closure&, Vec3f) {
  return 1.0f;
}

}  // namespace gdpt::oren_nayar
