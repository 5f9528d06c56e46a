// Russian roulette: the probability of continuing a path after a scattering vertex.
//
// q = min(sqrt(max component of the throughput), 1), decided after scattering at vertex
// `rr_depth` and later ones (vertex 0 is the camera ray's hit; RenderSettings::rr_depth, 3), PT
// and G-PT alike (after glossy bounces it takes effect past the next hit: roulette_past_next_hit).
// The square root (Cycles' rule) ends dim paths less eagerly than q = throughput, and with no cap
// below 1 a bright path is never stopped; it beat q = min(throughput, 0.95) in relMSE x cost
// (docs/integrator.md, "Russian roulette").
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec.h"
#include "render/features.h"
#include "shaders/closure.h"

namespace gdpt {

// Continuation probability for a path whose throughput (BSDF weights over densities, past
// roulette divisions included) is `beta`. 1 means "continue without drawing a number".
inline float roulette_continuation(Vec3f beta) {
  return std::min(std::sqrt(max_component(beta)), 1.0f);
}

// Whether the roulette after a bounce that sampled `lobe` takes effect past the next hit, in
// Cycles' order: the sampled ray is traced either way, what it finds first (a lamp, an emitter,
// the world) counts undivided, and only what follows is stopped or divided by q. So after glossy
// and specular bounces, whose lamp light comes mostly from their sampled rays, in scenes where a
// ray can find emission (`scene_features`, features.h). After a diffuse bounce next-event
// estimation already carries nearly all of it, and the roulette takes effect at once (Cycles'
// order after every bounce costs more rays for the same error).
inline bool roulette_past_next_hit(uint32_t lobe, uint32_t scene_features) {
  return !(lobe & kLobeDiffuse) &&
         (scene_features & (kSceneAnalyticLights | kSceneWorld | kSceneEmissiveTriangles)) != 0;
}

}  // namespace gdpt
