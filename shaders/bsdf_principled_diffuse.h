// Principled v1 diffuse as Cycles 3.4 (PRINCIPLED_DIFFUSE_FULL): Burley's diffuse with the
// retro-reflection term separated as in Burley 2015. With F(x) = (1 - x)^5, r = roughness
// (Closure::alpha, Blender roughness, not squared), RR = r (1 + dot(wi, wo)):
//   f |cos_o| = weight / pi * cos_o * [ (1 - F_v/2)(1 - F_l/2) + RR (F_l + F_v + F_l F_v (RR - 1))
//   ]
// Sampled cosine-weighted, as Cycles.
#pragma once

#include "shaders/closure.h"
#include "shaders/diffuse_sampling.h"
#include "shaders/lobe_util.h"
#include "shaders/sampling.h"

namespace gdpt::principled_diffuse {

inline float schlick_weight(float c) {
  const float m = std::clamp(1.0f - c, 0.0f, 1.0f);
  const float m2 = m * m;
  return m2 * m2 * m;
}

inline Spectrum eval(const Closure& c, Vec3f wi_, Vec3f wo_) {
  if (!(wi_.z * wo_.z > 0.0f)) return Spectrum(0.0f);
  const MirroredPair p(wi_, wo_);
  const float nl = p.wo.z, nv = p.wi.z;
  const float fl = schlick_weight(nl), fv = schlick_weight(nv);
  const float lambert = (1.0f - 0.5f * fv) * (1.0f - 0.5f * fl);
  // 2 cos^2(theta_d) = 1 + cos(angle between wi and wo).
  const float rr = c.alpha * (dot(p.wi, p.wo) + 1.0f);
  const float retro = rr * (fl + fv + fl * fv * (rr - 1.0f));
  return c.weight * (kInvPi * nl * (lambert + retro));
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

}  // namespace gdpt::principled_diffuse
