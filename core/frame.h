// Orthonormal shading frame: BSDFs work in local coordinates with the normal on +z.
#pragma once

#include "core/vec.h"

namespace gdpt {

struct Frame {
  Vec3f s, t, n;

  Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
  Frame(Vec3f s_, Vec3f t_, Vec3f n_) : s(s_), t(t_), n(n_) {}

  // Branchless basis from a unit normal (Duff et al. 2017, "Building an Orthonormal Basis,
  // Revisited").
  explicit Frame(Vec3f normal) : n(normal) {
    const float sign = std::copysign(1.0f, normal.z);
    const float a = -1.0f / (sign + normal.z);
    const float b = normal.x * normal.y * a;
    s = Vec3f(1.0f + sign * normal.x * normal.x * a, sign * b, -sign * normal.x);
    t = Vec3f(b, sign + normal.y * normal.y * a, -normal.y);
  }

  // always_inline: GCC kept to_local out of line in the path tracer's trace loop (a call with
  // Vec3f split over registers for three dot products).
  [[gnu::always_inline]] Vec3f to_local(const Vec3f& v) const {
    return {dot(v, s), dot(v, t), dot(v, n)};
  }
  [[gnu::always_inline]] Vec3f to_world(const Vec3f& v) const {
    return s * v.x + t * v.y + n * v.z;
  }
};

// Local-frame trigonometry (normal = +z).
inline float cos_theta(Vec3f w) {
  return w.z;
}
inline float abs_cos_theta(Vec3f w) {
  return std::fabs(w.z);
}
inline bool same_hemisphere(Vec3f a, Vec3f b) {
  return a.z * b.z > 0.0f;
}

}  // namespace gdpt
