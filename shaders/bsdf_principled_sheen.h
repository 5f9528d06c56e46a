// Principled v1 sheen as Cycles 3.4 (bsdf_principled_sheen.h, Burley 2012): a grazing-angle
// retro-reflective layer over the diffuse. With F(x) = (1 - x)^5 and h the half vector,
//   f |cos_o| = weight * F(dot(wo, h)) * cos_o
// (no 1/pi: Cycles' definition). Sampled cosine-weighted, as Cycles. Lobe selection uses Cycles'
// estimate of its average, F(cos_i) cos_i, floored so the lobe stays reachable at normal incidence
// (where that estimate is 0 but the lobe is not).
#pragma once

#include "shaders/bsdf_principled_diffuse.h"
#include "shaders/closure.h"
#include "shaders/diffuse_sampling.h"
#include "shaders/lobe_util.h"

namespace gdpt::principled_sheen {

inline Spectrum eval(const Closure& c, Vec3f wi_, Vec3f wo_) {
  if (!(wi_.z * wo_.z > 0.0f)) return Spectrum(0.0f);
  const MirroredPair p(wi_, wo_);
  const Vec3f h = p.wi + p.wo;
  const float l2 = length_squared(h);
  if (!(l2 > 0.0f)) return Spectrum(0.0f);
  const float cos_d = dot(p.wo, h) / std::sqrt(l2);
  return c.weight * (principled_diffuse::schlick_weight(cos_d) * p.wo.z);
}

inline float pdf(const Closure&, Vec3f wi, Vec3f wo) {
  return cosine_lobe_pdf(wi, wo);
}

inline BsdfSample sample(const Closure& c, Vec3f wi, float, Vec2f u) {
  return sample_cosine_lobe(wi, u, [&](Vec3f wo) { return eval(c, wi, wo); });
}

inline float albedo_hint(const Closure&, Vec3f wi) {
  const float c = std::fabs(wi.z);
  return std::max(principled_diffuse::schlick_weight(c) * c, 0.02f);
}

}  // namespace gdpt::principled_sheen
