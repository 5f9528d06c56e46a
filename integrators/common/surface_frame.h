// The shading frame of a surface hit as Cycles sets it up, for PT and G-PT alike: normals
// flipped towards the incoming ray for back faces (materials learn the side from
// ShadingContext::front_facing), and a shading normal that would mirror the incoming direction
// below the surface rotated towards the geometric one (valid_reflection_normal), which keeps
// smooth shading continuous at silhouettes instead of snapping to the flat normal.
#pragma once

#include "core/valid_reflection.h"
#include "core/vec.h"
#include "render/embree_scene.h"

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

}  // namespace gdpt
