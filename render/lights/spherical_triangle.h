// Uniform sampling of the solid angle a triangle subtends from a point (Arvo 1995, "Stratified
// Sampling of Spherical Triangles"), as Cycles does for large emissive triangles. Density
// 1 / solid_angle over the triangle's projection.
//
// Parameters: reference point o and the triangle's vertices p0, p1, p2 (world space).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec.h"

namespace gdpt::lights {

class SphericalTriangle {
 public:
  SphericalTriangle(Vec3f o, Vec3f p0, Vec3f p1, Vec3f p2)
      : a_(normalize(p0 - o)), b_(normalize(p1 - o)), c_(normalize(p2 - o)) {
    // Interior angles from the normals of the great circles through each pair of vertices.
    const Vec3f n_ab = safe_normalize(cross(a_, b_));
    const Vec3f n_bc = safe_normalize(cross(b_, c_));
    const Vec3f n_ca = safe_normalize(cross(c_, a_));
    alpha_ = safe_acos(-dot(n_ab, n_ca));
    const float beta = safe_acos(-dot(n_bc, n_ab));
    const float gamma = safe_acos(-dot(n_ca, n_bc));
    solid_angle_ = alpha_ + beta + gamma - kPi;
    if (!(solid_angle_ > 0.0f) || !std::isfinite(solid_angle_)) solid_angle_ = 0.0f;
    sin_alpha_ = std::sin(alpha_);
    cos_alpha_ = std::cos(alpha_);
    cos_c_ = dot(a_, b_);
  }

  float solid_angle() const { return solid_angle_; }

  // Unit direction from o into the triangle for u in [0,1)^2.
  Vec3f sample(Vec2f u) const {
    // 1. Choose the sub-triangle A B C' of area u.x * solid_angle: find C' on arc A C.
    const float area = u.x * solid_angle_;
    const float s = std::sin(area - alpha_), t = std::cos(area - alpha_);
    const float uu = t - cos_alpha_;
    const float vv = s + sin_alpha_ * cos_c_;
    const float q = std::clamp(
        ((vv * t - uu * s) * cos_alpha_ - vv) / ((vv * s + uu * t) * sin_alpha_), -1.0f, 1.0f);
    const Vec3f c_perp = safe_normalize(c_ - a_ * dot(c_, a_));
    const Vec3f c_hat = a_ * q + c_perp * std::sqrt(std::max(0.0f, 1.0f - q * q));
    // 2. Choose a point on arc B C' uniformly in the cosine to B.
    const float z = 1.0f - u.y * (1.0f - dot(c_hat, b_));
    const Vec3f p_perp = safe_normalize(c_hat - b_ * dot(c_hat, b_));
    return normalize(b_ * z + p_perp * std::sqrt(std::max(0.0f, 1.0f - z * z)));
  }

 private:
  static float safe_acos(float c) { return std::acos(std::clamp(c, -1.0f, 1.0f)); }
  static Vec3f safe_normalize(Vec3f v) {
    const float l2 = length_squared(v);
    return l2 > 0.0f ? v / std::sqrt(l2) : Vec3f(0.0f);
  }

  Vec3f a_, b_, c_;
  float alpha_ = 0.0f, sin_alpha_ = 0.0f, cos_alpha_ = 1.0f, cos_c_ = 1.0f;
  float solid_angle_ = 0.0f;
};

}  // namespace gdpt::lights
