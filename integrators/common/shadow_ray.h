// Shadow rays towards a light sample, for PT and G-PT alike.
#pragma once

#include <limits>

#include "core/vec.h"
#include "render/embree_scene.h"
#include "shaders/bsdf.h"

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

// Whether a light sample in the local direction `wo` (`cos_ng`: its cosine with the geometric
// normal facing the incoming ray) may be shaded at `hit`: the closures' side test, or, where that
// fails only because the light is below the flat facet of a smooth-shaded triangle whose shadow
// rays start lifted (EmbreeScene::lifts_shadow_rays), the shading normal alone, as Cycles: the
// lifted shadow ray then finds whether the facet hides the light.
inline bool light_side_ok(const EmbreeScene& bvh, const SurfaceHit& hit, const ClosureSet& cs,
                          Vec3f wo, float cos_ng) {
  if (cs.side_ok(wo, cos_ng)) return true;
  return wo.z > 0.0f && cos_ng < 0.0f && bvh.lifts_shadow_rays(hit);
}

// The origin of a light sample's shadow ray from `hit` along the unit direction `dir`, `ng` the
// geometric normal on either side: the shadow terminator start (EmbreeScene::shadow_ray_start,
// as Cycles for light samples only, not for BSDF-sampled rays), moved off the surface on the side
// `dir` leaves to. `plain`: the hit's own offset origin on that side, used when nothing is lifted.
inline Vec3f light_ray_origin(const EmbreeScene& bvh, const SurfaceHit& hit, Vec3f ng, Vec3f dir,
                              Vec3f plain) {
  const Vec3f start = bvh.shadow_ray_start(hit, dir);
  if (start == hit.position) return plain;
  return offset_ray_origin(start, dot(dir, ng) > 0.0f ? ng : -ng, bvh.offset_scale());
}

}  // namespace gdpt
