// atan2 for the light samplers' hot paths: glibc's atan2f pays for generality (a
// division, a call to atanf and error handling); this one is a polynomial, with an absolute error
// below 4e-7 rad (about 1.3 ulp near pi) over all quadrants (tests/integrator/test_atan2_fast.cpp).
//
// Method: reduce to a = min(|x|, |y|) / max(|x|, |y|) in [0, 1], evaluate atan(a) = a P(a^2)
// with a degree-7 polynomial P (fitted here as a near-minimax approximation of atan(a) / a on
// [0, 1] by iteratively reweighted least squares on Chebyshev nodes), then undo the reduction by
// octant. atan2(0, 0) is 0, like std::atan2.
#pragma once

#include <cmath>

#include "core/vec.h"

namespace gdpt {

inline float atan2_fast(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float hi = std::max(ax, ay), lo = std::min(ax, ay);
  const float a = hi > 0.0f ? lo / hi : 0.0f;
  const float s = a * a;
  float p = -0.004693277180194855f;
  p = p * s + 0.024252410978078842f;
  p = p * s - 0.05948641151189804f;
  p = p * s + 0.09914294630289078f;
  p = p * s - 0.1401948183774948f;
  p = p * s + 0.19969724118709564f;
  p = p * s - 0.33331990242004395f;
  p = p * s + 0.9999998807907104f;
  float r = p * a;
  if (ay > ax) r = 0.5f * kPi - r;
  if (x < 0.0f) r = kPi - r;
  return std::copysign(r, y);
}

}  // namespace gdpt
