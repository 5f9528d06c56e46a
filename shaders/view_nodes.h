// Input nodes that read the view of a hit: Fresnel and Layer Weight, as Cycles 3.4 computes them
// (kernel/svm/fresnel.h). `cos_in` is the cosine between the incoming direction (towards the
// previous vertex) and the node's normal; `backfacing` says the ray hit the back of the surface.
#pragma once

#include <algorithm>
#include <cmath>

#include "shaders/fresnel.h"

namespace gdpt {

// Fresnel node: the dielectric reflectance of IOR `ior` (from outside: the IOR itself, from the
// back: its inverse), IOR clamped away from 0.
inline float fresnel_node(float ior, float cos_in, bool backfacing) {
  const float eta = std::max(ior, 1e-5f);
  return fresnel_dielectric(cos_in, backfacing ? 1.0f / eta : eta);
}

// Layer Weight's Fresnel output: the reflectance of the IOR 1 / (1 - blend), inverted on back
// faces.
inline float layer_weight_fresnel(float blend, float cos_in, bool backfacing) {
  const float eta = std::max(1.0f - blend, 1e-5f);
  return fresnel_dielectric(cos_in, backfacing ? eta : 1.0f / eta);
}

// Layer Weight's Facing output: 1 - |cos|^e with e = 2 blend below a half and 0.5 / (1 - blend)
// above (blend kept below 1); exactly 1 - |cos| at a half.
inline float layer_weight_facing(float blend, float cos_in) {
  float f = std::fabs(cos_in);
  if (blend != 0.5f) {
    const float b = std::clamp(blend, 0.0f, 1.0f - 1e-5f);
    f = std::pow(f, b < 0.5f ? 2.0f * b : 0.5f / (1.0f - b));
  }
  return 1.0f - f;
}

}  // namespace gdpt
