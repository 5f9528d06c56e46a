// Next-event estimation of a base vertex and its shift to the offsets (Kettunen et al. 2015,
// section 5.2): the offsets reuse the base's light sample, the same point on the light; a
// not-connected pair reconnects to it only when both vertices are diffuse, else the pair drops
// light sampling on both sides and weights the matching BSDF-sampled hit without it.
#pragma once

#include "integrators/gpt/gpt_context.h"
#include "integrators/gpt/path_scratch.h"
#include "render/light_sampler.h"

namespace gdpt {

// The offset's light sample for a not-connected pair: the same point on the light (same
// direction for infinite lights) as the base's sample `ls`, seen from y. Resampling with the
// same random numbers gives that point for area-sampled lights, the world and the sun;
// solid-angle-sampled spheres are evaluated by intersecting the light towards the point.
bool offset_light(const LightSampler& lights, Vec3f y, float u_select, Vec2f u_light,
                  const LightSample& ls, LightSample& out);

// How an offset vertex `v` sees its light sample `lo` (offset_light() of the base's `ls`): its
// local direction `wo`, the BSDF value `f` and density `pdf` towards it, and the lamp's light
// arriving (`lo.radiance` times the transmittance of delta lamps' rays).
enum class Arrival : uint8_t { None, Blocked, Visible };  // None: no BSDF value or no radiance
Arrival offset_arrival(const GptContext& g, const Vertex& v, const LightSample& ls, LightSample& lo,
                       Vec3f& wo, Spectrum& f, float& pdf, ClosureSet& scratch, uint32_t& rays);

// Squared distance of two unit normals of the same surface point evaluated from two reference
// points (rounding only); receiver-facing discs differ by the angle between the two receivers
// seen from the light, far above this.
inline constexpr float kSameNormal2 = 1e-8f;

// The light sample `ls` (drawn with u_select, u_light) at the base vertex `base`: the base's PT
// estimate into out.primal, and each offset's pair term w (C' - C) into its gradient. Open
// offsets (bit k of open_mask) are evaluated per pair, merged ones through add_merged().
void nee_pairs(const GptContext& g, const Vertex& base, const BasePath& bp, const LightSample& ls,
               float u_select, Vec2f u_light, unsigned open_mask, PathScratch& scratch,
               SampleResult& out);

}  // namespace gdpt
