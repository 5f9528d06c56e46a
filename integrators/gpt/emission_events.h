// Emission events at the end of a base segment (Kettunen et al. 2015, section 5.2): an analytic
// light the segment crosses, the world it escapes to, or an emissive triangle it hits. Each adds
// to the primal I (the PT estimate) and, for every offset, the pair term w (C' - C) of the offset
// path's matching event to that offset's gradient half. Events are processed per pair whenever
// the base OR the offset finds emission: a half-vector offset has its own end vertex and can
// reach a light the base misses.
#pragma once

#include "integrators/gpt/gpt_context.h"
#include "integrators/gpt/path_scratch.h"
#include "render/light_sampler.h"

namespace gdpt {

// The base's segment x_d -> x_{d+1} as the emission events see it.
struct SegmentEnd {
  const Vertex* base;           // x_d
  shift::VertexType base_type;  // x_d's classification by roughness
  const Ray* ray;               // the segment
  bool delta;                   // sampled by a delta lobe: no light technique competes
  shift::Vec3d seg_b;           // its BSDF value f(x_d) (not divided by the density)
  float pdf_b;                  // its solid-angle density
  bool found;                   // x_{d+1} is a surface (not the world, not a holdout)
  bool base_holdout;            // the segment ended at a holdout
  const SurfaceHit* next;       // x_{d+1} when found
  bool camera_path;             // still the camera's ray (transparent crossings only)
  bool world_seen;              // the world emits into this segment
  bool light_hit;               // the segment crosses an analytic light before x_{d+1}: `lh`
  const LightHit* lh;
  ClosureSet* scratch;  // closures for the walk of shadow caustics' rule (CausticChain::weight)
};

// (a) Analytic lights the segment crosses before its end. Returns the merged offsets' event
// part (add_merged()).
shift::Vec3d lamp_events(const GptContext& g, const SegmentEnd& e, const BasePath& bp,
                         unsigned open_mask, Offset* off, SampleResult& out);

// (b) the world, (c) an emissive triangle at the end of the segment. Adds the merged offsets'
// event part to `emit_merged`.
void end_events(const GptContext& g, const SegmentEnd& e, const BasePath& bp, unsigned open_mask,
                Offset* off, shift::Vec3d& emit_merged, SampleResult& out);

}  // namespace gdpt
