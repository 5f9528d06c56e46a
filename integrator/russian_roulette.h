// Russian roulette: the probability of continuing a path after a scattering vertex.
//
// q = min(sqrt(max component of the throughput), 1), decided after scattering at vertex
// `rr_depth` and later ones (vertex 0 is the camera ray's hit; RenderSettings::rr_depth, 3), PT
// and G-PT alike (after glossy bounces it takes effect past the next hit: path_tracer.cpp). The
// square root (Cycles' rule) ends dim paths less eagerly than q = throughput, and with no cap below
// 1 a bright path is never stopped. Against the former rule (q = min(throughput, 0.95) from vertex
// 5), relMSE x instructions per sample on bench_integrator's scenes is 7% / 14% / 1% lower (Cornell
// box / textured box / 4-bounce Blender scene), and bench_equal_time's G-PT errors are unchanged
// within noise: docs/integrator.md, "Russian roulette".
#pragma once

#include <algorithm>
#include <cmath>

#include "integrator/math/vec.h"

namespace gdpt {

// Continuation probability for a path whose throughput (BSDF weights over densities, past
// roulette divisions included) is `beta`. 1 means "continue without drawing a number".
inline float roulette_continuation(Vec3f beta) {
  return std::min(std::sqrt(max_component(beta)), 1.0f);
}

}  // namespace gdpt
