// Shadow rays towards a light sample, for PT and G-PT alike.
#pragma once

#include <limits>

#include "core/vec.h"
#include "render/embree_scene.h"

namespace gdpt {

// A shadow ray to a finite point runs along the segment itself, t in [0, kShadowEnd]: it stops
// short of the light's own surface (emissive triangles are geometry too) by a fraction of the
// segment, so that every ray towards the same point, from any origin, stops at the same relative
// place; an occlusion query needs no unit direction.
inline constexpr float kShadowEnd = 1.0f - 1e-4f;

// From `origin` (already offset off its surface) to the point `target`.
inline Ray shadow_ray_to_point(Vec3f origin, Vec3f target, uint32_t kind) {
  Ray r;
  r.origin = origin;
  r.direction = target - origin;
  r.t_min = 0.0f;
  r.t_max = kShadowEnd;
  r.kind = kind;
  return r;
}

// From `origin` along the unit direction `dir` to infinity (the world, the sun).
inline Ray shadow_ray_to_infinity(Vec3f origin, Vec3f dir, uint32_t kind) {
  Ray r;
  r.origin = origin;
  r.direction = dir;
  r.t_min = 0.0f;
  r.t_max = std::numeric_limits<float>::infinity();
  r.kind = kind;
  return r;
}

}  // namespace gdpt
