// Warps from the unit square to directions, with their densities (solid angle).
#pragma once

#include <cmath>

#include "integrator/math/vec.h"

namespace gdpt {

// Concentric (Shirley-Chiu) map of the unit square onto the unit disk: keeps strata compact,
// which matters with the low-discrepancy sampler.
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
