// Ashikhmin velvet (Blender's Velvet BSDF, Cycles' bsdf_ashikhmin_velvet): a sheen-like
// reflection with the microfacet distribution D(h) = exp(-cot^2 / s^2) / (pi s^2 sin^4) of the
// half vector, shadowing min(1, 2 cos(n,h) cos(n,w) / cos(w,h)) for w = wi, wo, and
// f cos(theta_o) = D G / (4 cos(theta_i)); s = max(Sigma, 0.01). Uniform hemisphere sampling.
// Two-sided like every reflection lobe (lobe_util.h).
#pragma once

#include <algorithm>
#include <cmath>

#include "shaders/closure.h"
#include "shaders/lobe_util.h"
#include "shaders/sampling.h"

namespace gdpt::velvet {

// Closure::alpha holds Sigma. The value in the upper hemisphere (wi.z, wo.z > 0).
inline float value_upper(float sigma, Vec3f wi, Vec3f wo) {
  if (!(wi.z > 0.0f && wo.z > 0.0f)) return 0.0f;
  const Vec3f h = normalize(wi + wo);
  const float cos_nh = h.z, cos_ho = std::fabs(dot(wi, h));
  if (!(std::fabs(cos_nh) < 1.0f - 1e-5f && cos_ho > 1e-5f)) return 0.0f;
  const float ratio = std::max(cos_nh / cos_ho, 1e-5f);
  const float g = std::min(1.0f, 2.0f * std::min(std::fabs(ratio * wi.z), std::fabs(ratio * wo.z)));
  const float sin2 = 1.0f - cos_nh * cos_nh;
  const float inv_s2 = 1.0f / (std::max(sigma, 0.01f) * std::max(sigma, 0.01f));
  const float d = std::exp(-(cos_nh * cos_nh / sin2) * inv_s2) * inv_s2 * kInvPi / (sin2 * sin2);
  return 0.25f * d * g / wi.z;
}

inline Spectrum eval(const Closure& c, Vec3f wi, Vec3f wo) {
  const MirroredPair m(wi, wo);
  return c.weight * value_upper(c.alpha, m.wi, m.wo);
}

inline float pdf(const Closure&, Vec3f wi, Vec3f wo) {
  return wi.z * wo.z > 0.0f ? 0.5f * kInvPi : 0.0f;
}

inline BsdfSample sample(const Closure& c, Vec3f wi, float, Vec2f u) {
  BsdfSample s;
  if (wi.z == 0.0f) return s;
  const float z = u.x, r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.0f * kPi * u.y;
  if (z <= 0.0f) return s;
  s.wo = flip_z(Vec3f(r * std::cos(phi), r * std::sin(phi), z), wi.z < 0.0f ? -1.0f : 1.0f);
  s.pdf = 0.5f * kInvPi;
  s.value = eval(c, wi, s.wo);
  s.lobe = kLobeReflection | kLobeDiffuse;
  s.roughness = 1.0f;
  s.valid = true;
  return s;
}

inline float albedo_hint(const Closure&, Vec3f) {
  return 1.0f;
}

}  // namespace gdpt::velvet
