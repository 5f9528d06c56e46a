// Manifold next-event estimation (integrators/common/manifold_nee.h) of a base vertex and its
// shift to the offsets: each offset reuses the base's light point (Jacobian 1 in the light
// point's area measure). What a light sample estimates at a receiver depends on its segment: one
// that crosses casters is the refracted path through them (shared with its BSDF-sampled copies
// by manifold_nee_weight(), which each side of a pair applies to its own path: the pair weights
// stay those of one technique), a clear one the plain light sample. An offset evaluates its own
// segment so: at the caster's silhouette a pair mixes the two (here and in nee_pairs()).
#pragma once

#include "integrators/common/manifold_nee.h"
#include "integrators/gpt/gpt_context.h"
#include "integrators/gpt/path_scratch.h"
#include "render/light_sampler.h"

namespace gdpt {

// For a light sample `ls` that runs shadow caustics at `base` (runs_shadow_caustics): false when
// no caster stands on the base's straight segment to the light point (nee_pairs() then takes
// the sample); else the base's estimate goes into out.primal, each offset's pair term into its
// gradient, and the plain light sample (blocked by the casters) is not taken.
bool caustic_pairs(const GptContext& g, const Vertex& base, const BasePath& bp,
                   const LightSample& ls, float u_select, Vec2f u_light, unsigned open_mask,
                   PathScratch& scratch, SampleResult& out);

// The caustic path from vertex `v` to the light point of `ls`: its transport (manifold NEE's MIS
// weight for a path leaving v with `share` included) and direction in v's frame (valid only when
// found and on a side v's closures take light from).
struct CausticEvent {
  Spectrum transport{0.0f};
  Vec3f wo;
  int casters = 0;  // on the straight segment
  bool valid = false;
};
CausticEvent caustic_event(const GptContext& g, const Vertex& v, const LightSample& ls,
                           const CausticShare& share, PathScratch& scratch, uint32_t& rays);

}  // namespace gdpt
