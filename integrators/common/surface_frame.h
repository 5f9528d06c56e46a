// The shading frame of a surface hit as Cycles sets it up, for PT and G-PT alike: normals
// flipped towards the incoming ray for back faces (materials learn the side from
// ShadingContext::front_facing), and a shading normal that would mirror the incoming direction
// below the surface rotated towards the geometric one (valid_reflection_normal), which keeps
// smooth shading continuous at silhouettes instead of snapping to the flat normal.
#pragma once

#include <cmath>

#include "core/frame.h"
#include "core/valid_reflection.h"
#include "core/vec.h"
#include "render/embree_scene.h"
#include "shaders/bsdf.h"

namespace gdpt {

struct SurfaceFrame {
  Vec3f ng;      // geometric normal on the side of the incoming ray
  Vec3f ns;      // shading normal, same side
  bool rotated;  // ns is not the hit's shading normal (the reflection check replaced it)
};

// `wi_world`: unit direction from the hit back along the incoming ray.
inline SurfaceFrame facing_frame(const SurfaceHit& hit, Vec3f wi_world) {
  SurfaceFrame f;
  f.ng = hit.front_facing ? hit.geometric_normal : -hit.geometric_normal;
  f.ns = valid_reflection_normal(hit.front_facing ? hit.shading_normal : -hit.shading_normal, f.ng,
                                 wi_world, f.rotated);
  return f;
}

// The local frame of a shading point with normal `ns` (unit, world): about the normal alone, or,
// where a lobe is anisotropic, with its x axis on that lobe's tangent projected onto the tangent
// plane (Cycles' make_orthonormals_tangent), the frame its Rotation turns from (lobes of other
// tangents are turned to theirs in shading_closures()). G-PT's shifts copy local directions, so
// each path's vertex is in its own tangent frame.
inline Frame shading_frame(Vec3f ns, const ClosureSet& closures) {
  Vec3f t;
  if (!closures.anisotropic_tangent(t)) [[likely]]
    return Frame(ns);
  const Vec3f s = t - ns * dot(t, ns);
  const float len2 = length_squared(s);
  if (!(len2 > 1e-20f) || !std::isfinite(len2)) return Frame(ns);
  const Vec3f x = s / std::sqrt(len2);
  return Frame(x, cross(ns, x), ns);
}

}  // namespace gdpt
