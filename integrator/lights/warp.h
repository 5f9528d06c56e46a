// Sample warps shared by the light types: concentric disk, uniform sphere, uniform triangle.
// All map [0,1)^2 to the domain; the densities are stated next to each.
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

}  // namespace gdpt::lights
