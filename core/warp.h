// Sample warps shared by the light types: uniform sphere, uniform triangle (the concentric disk
// is core/warp_disk.h).
// All map [0,1)^2 to the domain; the densities are stated next to each.
#pragma once

#include <cmath>

#include "core/frame.h"
#include "core/vec.h"
#include "core/warp_disk.h"

namespace gdpt::lights {

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
