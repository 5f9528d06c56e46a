// Diffuse transmission: f = weight / pi on the side of the surface opposite wi (Blender's
// Translucent BSDF, Cycles' bsdf_translucent), cosine-weighted sampling of that side.
#pragma once

#include <cmath>

#include "shaders/closure.h"
#include "shaders/lobe_util.h"
#include "shaders/sampling.h"

namespace gdpt::translucent {

inline Spectrum eval(const Closure& c, Vec3f wi, Vec3f wo) {
  if (!(wi.z * wo.z < 0.0f)) return Spectrum(0.0f);
  return c.weight * (std::fabs(wo.z) * kInvPi);
}

inline float pdf(const Closure&, Vec3f wi, Vec3f wo) {
  if (!(wi.z * wo.z < 0.0f)) return 0.0f;
  return std::fabs(wo.z) * kInvPi;
}

inline BsdfSample sample(const Closure& c, Vec3f wi, float, Vec2f u) {
  BsdfSample s;
  if (wi.z == 0.0f) return s;
  const Vec3f w = square_to_cosine_hemisphere(u);
  if (w.z <= 0.0f) return s;
  s.wo = flip_z(w, wi.z < 0.0f ? 1.0f : -1.0f);  // the side away from wi
  s.pdf = w.z * kInvPi;
  s.value = eval(c, wi, s.wo);
  s.lobe = kLobeTransmission | kLobeDiffuse;
  s.roughness = 1.0f;
  s.valid = true;
  return s;
}

inline float albedo_hint(const Closure&, Vec3f) {
  return 1.0f;
}

}  // namespace gdpt::translucent
