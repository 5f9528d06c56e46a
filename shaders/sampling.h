// Warps from the unit square to directions, with their densities (solid angle).
#pragma once

#include <cmath>

#include "core/vec.h"
#include "core/warp_disk.h"

namespace gdpt {

// Cosine-weighted direction on the upper hemisphere (z > 0); density cos(theta) / pi.
inline Vec3f square_to_cosine_hemisphere(Vec2f u) {
  const Vec2f d = square_to_disk_concentric(u);
  const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}

inline float cosine_hemisphere_pdf(float cos_theta) {
  return std::max(cos_theta, 0.0f) * kInvPi;
}

}  // namespace gdpt
