// The base path's running state and the per-thread working storage of the G-PT's trace().
#pragma once

#include <cstdint>

#include "integrators/common/data_passes.h"
#include "integrators/common/feature_passes.h"
#include "integrators/common/manifold_nee.h"
#include "integrators/common/path_state.h"
#include "integrators/gpt/camera_rays.h"
#include "integrators/gpt/offset_path.h"
#include "render/light_sampler.h"

namespace gdpt {

// One base path's outputs. Filled completely by trace() (reused across pixels: zeroing it per
// pixel cost a `rep stos`).
struct SampleResult {
  Spectrum primal;
  Spectrum emission;
  shift::Vec3d grad[kOffsets];  // the gradient halves G_k, sums of w (f'J - f)
  float alpha;  // Film::alpha(): 0 for a camera ray that reaches a transparent background
  uint8_t attempts, failures;
  uint32_t rays;
  DataSample data;        // Normal / Mist passes (DataPasses)
  FeatureSample feature;  // FeaturePasses
};

// The base path (the paper's x-bar) between vertices: the PT estimate's throughput beta = f / p,
// and for the pair weights f and p apart, in double (path densities are products of many
// solid-angle densities).
struct BasePath {
  PathState state;
  CausticChain caustic;  // whether a caustics lamp met now is manifold NEE's (manifold_nee.h)
  Spectrum beta{1.0f};
  shift::Vec3d fb{1.0, 1.0, 1.0};
  double pb = 1.0;
};

// Working storage of trace(), one per render_tile() call, reused across its samples: no
// allocation or large initialisation per sample (a ClosureSet holds kMaxClosures lobes).
struct PathScratch {
  Offset off[kOffsets];
  Vertex verts[2];  // base vertex and the next one, swapped per bounce
  CameraRow row;
  CameraGrid grid;
  // Next-event estimation per offset: as locals their default member initialisers ran on every
  // bounce.
  LightSample lo[kOffsets];
  Vec3f wo_o[kOffsets];
  Spectrum fo[kOffsets];
  // Per bounce, here rather than locals, for the same reason (eight doubles each). Each is read
  // only after trace() has set it.
  BaseStep step;
  shift::ReconnectionBase light_base;
  ClosureSet shadow_closures;  // surfaces a transparent shadow ray crosses
};

}  // namespace gdpt
