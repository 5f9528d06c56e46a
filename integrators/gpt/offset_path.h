// Offset paths (Kettunen et al. 2015, section 4): each follows the base path segment by segment
// through a shift T_ij (reconnection, half-vector copy, or the base's own segment once
// connected), carrying its throughput f' and density p' with the shift Jacobians multiplied in.
#pragma once

#include <cstdint>

#include "integrators/common/manifold_nee.h"
#include "integrators/gpt/gpt_context.h"
#include "integrators/gpt/path_vertex.h"
#include "integrators/gpt/shift_mapping.h"
#include "shaders/bsdf.h"

namespace gdpt {

// How far the offset has merged into the base: not yet, at the base's current vertex (it
// arrived there by reconnection and sees it from its own direction), or for good.
enum class Link : uint8_t { NotConnected, Recent, Connected };

// How the offset follows the base over one segment.
enum class Shift : uint8_t { Follow, RecentEval, Reconnect, ReconnectEnv, HalfVector, Failed };

struct Offset {
  bool active = false;  // traced for this sample (target pixel inside the image)
  bool alive = false;
  bool failed = false;  // died at some point (statistics)
  Link link = Link::NotConnected;
  Vertex v;         // own vertex while NotConnected
  Vec3f wi_world;   // Recent: direction towards the previous offset vertex, world
  Vec3f wi_shared;  // Recent: the same in the base vertex's local frame
  // Recent: the shared vertex's closures as the offset sees them (shared_closures()): the base's,
  // or for a material that reads the view its own evaluation (in v.own, free while merged).
  const ClosureSet* shared = nullptr;
  shift::Vec3d f;      // throughput up to the current vertex, Jacobians included
  double p = 0.0;      // density up to the current vertex, Jacobians included
  shift::Vec3d grad;   // sum of w (C' - C)
  bool nee_on = true;  // next-event estimation shifted for this pair at the current vertex
  // Segment from the current vertex (set per bounce).
  Shift shift = Shift::Failed;
  shift::Vec3d seg_value;
  double seg_pdf = 0.0, seg_jacobian = 1.0;
  bool seg_visible = true;  // Reconnect*: the offset vertex sees the target
  Vec3f seg_dir;            // world direction of the offset's segment
  // HalfVector: the offset's own next vertex.
  Ray ray;
  bool next_found = false;
  bool holdout_end = false;  // next_found is false because the segment met a holdout
  SurfaceHit next_hit;
  bool killed = false;   // the continuing path is not invertible / mismatched
  CausticChain caustic;  // shadow caustics' rule on the offset's own path (manifold_nee.h)
};

// The base's segment x_d -> x_{d+1} as the offsets' shift_segment() calls see it.
struct BaseStep {
  const Vertex* base;
  const BsdfSample* bs;
  shift::VertexType xd_type, next_type;
  Vec3f wo_world;
  bool found;
  const SurfaceHit* next;
  // A delta event at x_d: whether x_d's delta lobes make it in one direction
  // (ClosureSet::delta_event valid), as the half-vector copy requires of both vertices.
  bool base_delta_unique;
  uint32_t kind;      // RayKind of the base's segment: the offsets' segments see what it sees
  bool holdout_ends;  // a holdout at the segment's end ends the path (the camera path's)
  // The base's path state past this step: the offsets shade their next vertices by its
  // light-path rules (light_path_filters.h).
  const PathState* state;
  // Reconnection target x_{d+1} (when found): its base side, and the side the base arrives on.
  shift::ReconnectionBase target;
  bool base_front;
};

// BaseStep::base_delta_unique of the base's sample `bs` at `base`.
inline bool delta_event_unique(const Vertex& base, const BsdfSample& bs) {
  return bs.is_delta() &&
         base.closures->delta_event(base.wi, bs.lobe & (kLobeReflection | kLobeTransmission)).valid;
}

// Decides and evaluates the offset's version of the base segment x_d -> x_{d+1}: T_ij for one
// segment, its Jacobian, and the visibility or own hit it needs.
void shift_segment(const GptContext& g, Offset& o, const BaseStep& st, uint32_t& rays);

// Moves the offset to the end of the segment (`last`: the path ends there, no vertex needed);
// `state`: the base's path state there; `path`: its view (the offset's own vertex gets its own
// ray length).
void advance(const GptContext& g, Offset& o, bool last, const PathState& state,
             const PathView& path);

// Merged offsets: a connected offset shares the rest of the base path, so for an emission event
// with base contribution C = fb Y its contribution is C' = f' Y with the same technique
// densities, and the pair weight of shift::mis_weight_over_pdf factors into
// [p / (p^2 + p'^2)] [p_tech / (p_L^2 + p_B^2)]: w (C' - C) = (f' - fb) p / (p^2 + p'^2) E with
// the event part E = connected_event(Y, ...) common to all offsets. A dead offset is the same
// with f' = 0 and p' = 0 (it adds -w C, the base keeping both of its techniques). Equal up to
// rounding to the per-pair evaluation, which the open offsets still use.
inline void add_merged(Offset* off, shift::Vec3d fb, double pb, shift::Vec3d event) {
  for (int k = 0; k < kOffsets; ++k) {
    Offset& o = off[k];
    if (!o.active || (o.alive && o.link != Link::Connected)) continue;
    const shift::Vec3d f = o.alive ? o.f : shift::Vec3d();
    const double p = o.alive ? o.p : 0.0;
    const double d = pb * pb + p * p;
    if (d > 0.0) o.grad = o.grad + shift::mul(f - fb, event) * (pb / d);
  }
}

}  // namespace gdpt
