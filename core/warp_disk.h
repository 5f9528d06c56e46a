// Shirley-Chiu concentric map of the unit square onto the unit disk (uniform in area, density
// 1 / pi). Keeps strata compact, which matters with the low-discrepancy sampler; shared by the
// thin-lens camera, the diffuse BSDFs and the disc-shaped lights.
#pragma once

#include <cmath>

#include "core/sincos_fast.h"
#include "core/vec.h"

namespace gdpt {

// The angle is pi/4 * t or pi/2 - pi/4 * t with t in [-1, 1]: sin and cos of pi/4 * t by the
// polynomials alone (sincos_quarter), the second case by swapping them. libm's sincosf with its
// range reduction is not needed for these arguments.
inline Vec2f square_to_disk_concentric(Vec2f u) {
  const float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f};
  // Which of a and b is larger in magnitude is a coin flip per sample: selects, not branches.
  const bool wide = std::fabs(a) > std::fabs(b);
  const float num = wide ? b : a, den = wide ? a : b;
  float s, c;
  sincos_quarter((kPi / 4.0f) * (num / den), &s, &c);
  return {den * (wide ? c : s), den * (wide ? s : c)};
}

}  // namespace gdpt
