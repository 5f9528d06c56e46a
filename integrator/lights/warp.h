// Sample warps shared by the light types: uniform cone, uniform sphere, concentric disk,
// uniform triangle. All map [0,1)^2 to the domain; the densities are stated next to each.
#pragma once

#include <cmath>

#include "integrator/math/frame.h"
#include "integrator/math/vec.h"

namespace gdpt::lights {

// Shirley-Chiu concentric map to the unit disk (uniform in area, density 1 / pi).
inline Vec2f square_to_disk(Vec2f u) {
  const float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f};
  float r, phi;
  if (a * a > b * b) {
    r = a;
    phi = (kPi / 4.0f) * (b / a);
  } else {
    r = b;
    phi = (kPi / 2.0f) - (kPi / 4.0f) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

// Directions within angle theta_max of +z, uniform in solid angle. one_minus_cos_max is
// 1 - cos(theta_max), passed directly because it loses precision for tiny cones when formed
// from the cosine. Density 1 / (2 pi one_minus_cos_max).
inline Vec3f square_to_cone(Vec2f u, float one_minus_cos_max) {
  const float one_minus_cos = u.x * one_minus_cos_max;
  const float cos_theta = 1.0f - one_minus_cos;
  // sin^2 = (1 - cos)(1 + cos), accurate for small angles.
  const float sin_theta = std::sqrt(std::max(0.0f, one_minus_cos * (2.0f - one_minus_cos)));
  const float phi = 2.0f * kPi * u.y;
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

inline float cone_pdf(float one_minus_cos_max) {
  return 1.0f / (2.0f * kPi * one_minus_cos_max);
}

// Uniform direction on the sphere, density 1 / (4 pi).
inline Vec3f square_to_sphere(Vec2f u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Barycentric coordinates (b1, b2) uniform over a triangle (b0 = 1 - b1 - b2).
inline Vec2f square_to_triangle(Vec2f u) {
  const float s = std::sqrt(u.x);
  return {1.0f - s, u.y * s};
}

// 1 - cos(theta) for sin^2(theta) = s2 with theta <= 90 degrees, without cancellation.
inline float one_minus_cos_from_sin2(float s2) {
  return s2 / (1.0f + std::sqrt(std::max(0.0f, 1.0f - s2)));
}

}  // namespace gdpt::lights
