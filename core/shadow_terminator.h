// Cycles' shadow terminator geometry offset (Object > Shading > Shadow Terminator > Geometry
// Offset; Hanika 2021, "Hacking the shadow terminator"): a shadow ray leaving a smooth-shaded
// triangle near the terminator starts from the curved surface its vertex normals describe, not
// from the flat triangle, so low-poly spheres are not darkened by their own facets.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec.h"

namespace gdpt {

// A triangle's corners and their shading normals (unit), in one space.
struct SmoothTriangle {
  Vec3f p[3];
  Vec3f n[3];
};

// The lift of the point with barycentric weights `b` (of p[0], p[1], p[2]) towards the surface
// the corner normals describe, as a vector along the interpolated (unnormalised) normal.
// `ng`: the geometric normal on the side the ray leaves; on the other side of the interpolated
// normal the surface is pushed down instead. The height is a quadratic patch through the
// corners, bounded by the corners' tangent planes (the local linear envelope).
inline Vec3f smooth_surface_lift(const SmoothTriangle& t, Vec3f b, Vec3f ng) {
  const Vec3f* P = t.p;
  const Vec3f* N = t.n;
  const Vec3f at = P[0] * b.x + P[1] * b.y + P[2] * b.z;
  const Vec3f n = N[0] * b.x + N[1] * b.y + N[2] * b.z;
  // Quadratic patch: each edge bends by how much its end normals turn along it.
  const float e02 = dot(N[2] - N[0], P[0] - P[2]);
  const float e12 = dot(N[2] - N[1], P[1] - P[2]);
  const float e01 = dot(N[1] - N[0], P[1] - P[0]);
  float h = e02 * b.x * (b.x - 1.0f) + (e02 + e12 + e01) * b.x * b.y + e12 * b.y * (b.y - 1.0f);
  // side = +1: the corners' tangent planes lie above the point; -1: below.
  const float side = dot(n, ng) > 0.0f ? 1.0f : -1.0f;
  float envelope = 0.0f;
  for (int i = 0; i < 3; ++i) {
    const Vec3f a = P[(i + 1) % 3] - P[i], c = P[(i + 2) % 3] - P[i];
    const float reach = std::max(std::max(side * dot(a, N[i]), side * dot(c, N[i])), 0.0f);
    const float hi = std::max(side * dot(P[i] - at, N[i]) + reach, 0.0f);
    envelope = i == 0 ? hi : std::min(envelope, hi);
  }
  h = side > 0.0f ? std::max(envelope, 0.5f * h) : std::min(-envelope, 0.5f * h);
  return n * h;
}

// How much of the lift a shadow ray towards unit `l` takes, with `cutoff` the object's Geometry
// Offset: 1 at the terminator, 0 where the shading and geometric normals both face the light by
// more than the cutoff (and always 0 for cutoff 0), a ramp between.
// `ns`: the interpolated shading normal; `ng`: the geometric normal, both on the side the ray
// arrived from. `ng_side` is set to the geometric normal on the shading normal's side of `l`.
inline float terminator_lift_amount(float cutoff, Vec3f ns, Vec3f ng, Vec3f l, Vec3f& ng_side) {
  if (!(cutoff > 0.0f)) return 0.0f;
  const float cos_n = dot(ns, l);
  ng_side = cos_n < 0.0f ? -ng : ng;
  const float cos_s = std::fabs(cos_n), cos_g = dot(ng_side, l);
  const float ramp = cos_s < cutoff ? 2.0f - (cos_g + cos_s) / cutoff : 1.0f - cos_g / cutoff;
  return std::clamp(ramp, 0.0f, 1.0f);
}

// Cycles' shadow terminator shading offset (Object > Shading > Shadow Terminator > Shading
// Offset, after appleseed): the BSDF value of a reflected direction at angle a from the lobe's
// normal is scaled by max(cos(k a), 0) / cos(a), which darkens towards the terminator and moves
// it towards the light. k is the frequency multiplier of the setting `offset` in [0, 1]
// (Cycles' object.cpp: 1 / (1 - offset / 2)).
inline float terminator_frequency(float offset) {
  return 1.0f / (1.0f - 0.5f * offset);
}

// The factor for a direction of cosine `cos_wo` with the lobe's normal: 1 for k <= 1 and for
// directions at or below the lobe's horizon (transmission: Cycles leaves those alone).
inline float terminator_shading_factor(float cos_wo, float k) {
  if (!(k > 1.0f) || !(cos_wo > 0.0f)) return 1.0f;
  const float c = std::min(cos_wo, 1.0f);
  return std::max(std::cos(std::acos(c) * k), 0.0f) / c;
}

}  // namespace gdpt
