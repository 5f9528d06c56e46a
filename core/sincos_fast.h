// sin and cos together for the samplers' hot paths: glibc's sincosf pays for a general range
// reduction that these small arguments do not need; this one is a short polynomial
// with an absolute error below 2e-7 for |x| <= 1e5 (tests/integrator/test_sincos_fast.cpp).
//
// Method: x = q pi/2 + r with q the nearest integer and r in [-pi/4, pi/4] (reduction in double,
// exact enough for |x| far beyond what the samplers pass), then sin(r) = r (1 + r^2 S(r^2)) and
// cos(r) = 1 + r^2 C(r^2) with degree-3 / degree-4 polynomials fitted here as near-minimax
// approximations on [0, pi/4] (iteratively reweighted least squares on Chebyshev nodes; errors
// 4e-8 and 7e-8 in float), and the quadrant q mod 4 swaps and negates the pair.
#pragma once

#include <cmath>
#include <cstdint>

namespace gdpt {

// sin and cos of r in [-pi/4, pi/4]: the polynomials alone, for callers whose angle is already
// in that range (the concentric disk map).
inline void sincos_quarter(float r, float* sin_out, float* cos_out) {
  const float r2 = r * r;
  float s = -0.00019517300825100392f;
  s = s * r2 + 0.008332177996635437f;
  s = s * r2 - 0.16666655242443085f;
  *sin_out = r + r * (r2 * s);
  float c = 2.4390452381339855e-05f;
  c = c * r2 - 0.0013886763481423259f;
  c = c * r2 + 0.04166662320494652f;
  c = c * r2 - 0.5f;
  *cos_out = 1.0f + r2 * c;
}

inline void sincos_fast(float x, float* sin_out, float* cos_out) {
  const double q = std::nearbyint(double(x) * 0.6366197723675814);  // x / (pi / 2)
  float sin_r, cos_r;
  sincos_quarter(float(double(x) - q * 1.5707963267948966), &sin_r, &cos_r);
  const uint32_t quadrant = uint32_t(int64_t(q)) & 3u;
  const float a = (quadrant & 1u) ? cos_r : sin_r;  // sin(x) up to sign
  const float b = (quadrant & 1u) ? sin_r : cos_r;  // cos(x) up to sign
  *sin_out = (quadrant & 2u) ? -a : a;
  *cos_out = ((quadrant + 1u) & 2u) ? -b : b;
}

}  // namespace gdpt
