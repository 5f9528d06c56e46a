// The shading normal a BSDF uses at a hit, as Cycles 3.4 sets it (ensure_valid_reflection, applied
// to every BSDF node's normal): an interpolated, normal-mapped or bumped normal N can mirror the
// incoming direction I below the surface (R = 2 (N.I) N - I with R.Ng < 0), which lets light leak
// and makes silhouettes of smooth meshes go dark. Then N is rotated towards Ng, in the plane of N
// and Ng, just far enough that R.Ng reaches t = min(0.9 I.Ng, 0.01): the reflection is never
// shallower than needed, and never shallower than the incoming ray itself.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec.h"

namespace gdpt {

// The rotated normal, for valid_reflection_normal below (out of line: rare, and inlined it
// added register pressure to the path loop).
[[gnu::noinline, gnu::cold]] inline Vec3f rotate_to_valid_reflection(Vec3f ns, Vec3f ng, Vec3f wi,
                                                                     float iz, float t) {
  // In the frame (x, ng), x the unit direction of ns's part orthogonal to ng, the new normal is
  // (sqrt(1 - z^2), z) with R.ng = 2 (x ix + z iz) z - iz = t. Squaring gives a quadratic in
  // w = z^2: a w^2 - c w + (t + iz)^2 / 4 = 0, a = ix^2 + iz^2, c = a + iz t, with roots
  // (c +- b) / (2 a), b^2 = c^2 - a (t + iz)^2 = ix^2 (a - t^2).
  const Vec3f tangential = ns - ng * dot(ns, ng);
  const float tl = length(tangential);
  if (!(tl > 0.0f)) return ng;
  const Vec3f x = tangential / tl;
  const float ix = dot(wi, x);
  const float a = ix * ix + iz * iz;
  if (!(a > 0.0f)) return ng;
  const float b = std::sqrt(std::max(ix * ix * (a - t * t), 0.0f));
  const float c = iz * t + a;
  const float w1 = (c + b) / (2.0f * a), w2 = (c - b) / (2.0f * a);
  const auto usable = [](float w) { return w > 1e-5f && w <= 1.0f + 1e-5f; };
  const auto normal_of = [](float w) {
    return Vec2f(std::sqrt(std::max(1.0f - w, 0.0f)), std::sqrt(std::max(w, 0.0f)));
  };
  // Reflection height of a candidate (x, z): squaring admitted a root on the wrong side.
  const auto reflection_z = [&](Vec2f n) { return 2.0f * (n.x * ix + n.y * iz) * n.y - iz; };
  Vec2f chosen;
  if (usable(w1) && usable(w2)) {
    const Vec2f n1 = normal_of(w1), n2 = normal_of(w2);
    const float r1 = reflection_z(n1), r2 = reflection_z(n2);
    if (r1 >= 1e-5f && r2 >= 1e-5f)
      chosen = r1 < r2 ? n1 : n2;  // both valid: the shallower, closer to ns
    else
      chosen = r1 > r2 ? n1 : n2;
  } else if (usable(w1) || usable(w2)) {
    chosen = normal_of(usable(w1) ? w1 : w2);
  } else {
    return ng;
  }
  return x * chosen.x + ng * chosen.y;
}

// ns: unit shading normal; ng: unit geometric normal facing wi; wi: unit direction to the viewer.
// Returns ns when its reflection of wi is valid, else the rotated normal (ng when no rotation
// works).
// `rotated` is set when the result is not ns.
[[gnu::always_inline]] inline Vec3f valid_reflection_normal(Vec3f ns, Vec3f ng, Vec3f wi,
                                                            bool& rotated) {
  const float iz = dot(wi, ng);
  const float t = std::min(0.9f * iz, 0.01f);
  rotated = !(dot(ng, ns * (2.0f * dot(ns, wi)) - wi) >= t);
  if (!rotated) [[likely]]
    return ns;
  return rotate_to_valid_reflection(ns, ng, wi, iz, t);
}
inline Vec3f valid_reflection_normal(Vec3f ns, Vec3f ng, Vec3f wi) {
  bool rotated;
  return valid_reflection_normal(ns, ng, wi, rotated);
}

}  // namespace gdpt
