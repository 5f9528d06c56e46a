// Which closure set a shading point evaluates: Cycles 3.4 applies its bump shadowing term to the
// diffuse lobes of every closure whose normal differs from the interpolated one (a normal map or
// bump replaced it, or its reflection check rotated it: `sc->N != sd->N`). Such points get a copy
// of their closures marked with the interpolated normal (ClosureSet::set_bump_shadowing); all
// others keep theirs untouched, at the cost of one comparison. Objects with a shadow terminator
// shading offset get a copy too (ClosureSet::set_terminator_shift). Anisotropic lobes with
// tangents other than the first one's (which the frame follows) are turned to their own in a copy
// too (ClosureSet::orient_own_tangents): PT and every G-PT vertex, base or offset, in its own
// frame.
#pragma once

#include "core/frame.h"
#include "core/valid_reflection.h"
#include "render/embree_scene.h"
#include "shaders/bsdf.h"

namespace gdpt {

// The bump shadowing and terminator shift steps of shading_closures (below), with the same
// arguments.
inline const ClosureSet& bumped_closures(const ClosureSet& closures, ClosureSet& scratch,
                                         const SurfaceHit& hit, const Frame& frame, Vec3f ng,
                                         Vec3f wi, bool rotated) {
  const float k = hit.shading_instance ? hit.shading_instance->terminator_frequency : 1.0f;
  if (!hit.perturbed && !rotated && !(k > 1.0f)) [[likely]]
    return closures;
  const Vec3f interpolated = hit.perturbed ? hit.unperturbed_normal : hit.shading_normal;
  const Vec3f n0 = hit.front_facing ? interpolated : -interpolated;
  const bool shadowed = frame.n != n0;
  if (!shadowed && !(k > 1.0f)) return closures;
  if (&closures != &scratch) scratch.assign(closures);
  // The object's terminator shading offset, which PT and G-PT's shifted paths both evaluate
  // through the set, each with its own directions.
  scratch.set_terminator_shift(k);
  if (!shadowed) return scratch;
  scratch.set_bump_shadowing(frame.to_local(n0));
  // Lobes that keep the interpolated normal under the perturbation get it, with Cycles'
  // reflection check of their own.
  if (hit.perturbed && scratch.has_interpolated_normal_lobes())
    scratch.set_interpolated_normal(frame.to_local(valid_reflection_normal(n0, ng, wi)),
                                    frame.to_local(ng));
  return scratch;
}

// `closures`: the point's set (possibly `scratch` itself); `frame`: its shading frame, facing the
// incoming ray; `ng`: the geometric normal on the same side; `wi`: the unit direction to the
// previous vertex (world); `rotated`: the frame's normal is not the hit's shading normal (the
// reflection check or a fallback replaced it). Returns `closures` or `scratch`.
inline const ClosureSet& shading_closures(const ClosureSet& closures, ClosureSet& scratch,
                                          const SurfaceHit& hit, const Frame& frame, Vec3f ng,
                                          Vec3f wi, bool rotated) {
  const ClosureSet& bumped = bumped_closures(closures, scratch, hit, frame, ng, wi, rotated);
  if (!bumped.has_own_tangents()) [[likely]]
    return bumped;
  if (&bumped != &scratch) scratch.assign(bumped);
  scratch.orient_own_tangents(frame);
  return scratch;
}

}  // namespace gdpt
