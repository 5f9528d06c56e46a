// Shirley-Chiu concentric map of the unit square onto the unit disk (uniform in area, density
// 1 / pi). Keeps strata compact, which matters with the low-discrepancy sampler; shared by the
// thin-lens camera, the diffuse BSDFs and the disc-shaped lights.
#pragma once

#include <cmath>

#include "integrator/math/vec.h"

namespace gdpt {

inline Vec2f square_to_disk_concentric(Vec2f u) {
  const float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f};
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = (kPi / 4.0f) * (b / a);
  } else {
    r = b;
    phi = (kPi / 2.0f) - (kPi / 4.0f) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

}  // namespace gdpt
