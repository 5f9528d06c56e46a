// Helpers shared by the lobe implementations (bsdf_*.h).
//
// Every lobe implements, in the local shading frame (normal = +z, the geometric side, not
// flipped towards the viewer):
//   Spectrum eval(const Closure&, Vec3f wi, Vec3f wo)     f(wi, wo) |cos theta_o|
//   float pdf(const Closure&, Vec3f wi, Vec3f wo)         solid-angle density of sample()
//   BsdfSample sample(const Closure&, Vec3f wi, float u_choice, Vec2f u)
//   float albedo_hint(const Closure&, Vec3f wi)          rough albedo used to pick lobes
// Reflection-only lobes are two-sided like Cycles (whose shading normal faces the viewer): when
// wi is below the surface the problem is mirrored through the tangent plane.
#pragma once

#include "core/vec.h"
#include "shaders/closure.h"

namespace gdpt {

// Flips z of both directions when wi is below the surface; `sign` is the flip (+1 / -1).
struct MirroredPair {
  Vec3f wi, wo;
  float sign;
  MirroredPair(Vec3f wi_, Vec3f wo_) {
    sign = wi_.z < 0.0f ? -1.0f : 1.0f;
    wi = Vec3f(wi_.x, wi_.y, wi_.z * sign);
    wo = Vec3f(wo_.x, wo_.y, wo_.z * sign);
  }
};

inline Vec3f flip_z(Vec3f w, float sign) {
  return {w.x, w.y, w.z * sign};
}

// Luminance used for lobe selection; falls back to the mean for colours of zero luminance.
inline float selection_luminance(Spectrum c) {
  const float l = luminance(c);
  if (l > 0.0f) return l;
  return std::max(0.0f, (c.x + c.y + c.z) * (1.0f / 3.0f));
}

}  // namespace gdpt
