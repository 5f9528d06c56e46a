// Uniform sampling of the solid angle a rectangle subtends from a point (Urena, Fajardo, King
// 2013, "An Area-Preserving Parametrization for Spherical Rectangles"), as Cycles does for
// rectangular area lights. Density 1 / solid_angle over the rectangle's projection.
//
// Parameters: reference point o, rectangle corner s, unit orthogonal edge directions x and y,
// edge lengths ex and ey (the rectangle is s + [0, ex] x + [0, ey] y).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/atan2_fast.h"
#include "core/sincos_fast.h"
#include "core/vec.h"

namespace gdpt::lights {

class SphericalRectangle {
 public:
  SphericalRectangle(Vec3f o, Vec3f s, Vec3f x, Vec3f y, float ex, float ey) : o_(o), x_(x), y_(y) {
    z_ = cross(x, y);
    const Vec3f d = s - o;
    x0_ = dot(d, x);
    y0_ = dot(d, y);
    z0_ = dot(d, z_);
    // Work on the side of the plane facing o: z0 < 0.
    if (z0_ > 0.0f) {
      z0_ = -z0_;
      z_ = -z_;
    }
    x1_ = x0_ + ex;
    y1_ = y0_ + ey;
    // Interior angles of the spherical quadrilateral: g_i = acos(-dot(n_i, n_i+1)) with n_i the
    // unit normals of the planes through o and each edge. With corners v00 = (x0, y0, z0) etc.
    // the normals are two-term vectors, e.g. n0 = (0, z0, -y0) / r0, n1 = (-z0, 0, x1) / r1
    // (r their lengths), so cos g0 = x1 y0 / (r0 r1) and, by Lagrange's identity,
    // sin g0 = |z0| |v10| / (r0 r1): each angle is atan2(|z0| |corner|, +-x y) and the common
    // factor r_i r_i+1 drops out. Sums of two angles come from one complex product and one
    // atan2 (each pair sum lies in (0, 2 pi)), instead of four acos. The area is the angle sum
    // minus 2 pi.
    const float z2 = z0_ * z0_, az = std::fabs(z0_);
    const float l00 = az * std::sqrt(x0_ * x0_ + y0_ * y0_ + z2);
    const float l10 = az * std::sqrt(x1_ * x1_ + y0_ * y0_ + z2);
    const float l11 = az * std::sqrt(x1_ * x1_ + y1_ * y1_ + z2);
    const float l01 = az * std::sqrt(x0_ * x0_ + y1_ * y1_ + z2);
    const float g01 = angle_sum(x1_ * y0_, l10, -x1_ * y1_, l11);  // g0 + g1
    const float g23 = angle_sum(x0_ * y1_, l01, -x0_ * y0_, l00);  // g2 + g3
    b0_ = -y0_ / std::sqrt(z2 + y0_ * y0_);                        // n0.z
    b1_ = y1_ / std::sqrt(z2 + y1_ * y1_);                         // n2.z
    b0m1_ = -z2 / (z2 + y0_ * y0_);  // b0^2 - 1 without cancellation (grazing: b0^2 near 1)
    k_ = 2.0f * kPi - g23;
    solid_angle_ = g01 - k_;
  }

  float solid_angle() const { return solid_angle_; }

  // Point on the rectangle (world space) for u in [0,1)^2.
  Vec3f sample(Vec2f u) const {
    // 1. Pick the x coordinate by inverting the partial solid angle of the strip [x0, xu].
    const float au = u.x * solid_angle_ + k_;
    float sin_au, cos_au;
    sincos_fast(au, &sin_au, &cos_au);
    const float fu = (cos_au * b0_ - b1_) / sin_au;
    // The paper's cu = sign(fu) / sqrt(fu^2 + b0^2) and xu = -cu z0 / sqrt(1 - cu^2) fold into
    // xu = sign(fu) |z0| / sqrt(fu^2 + b0^2 - 1): one square root and one division on this
    // latency chain instead of two each (the shadow ray waits for the point).
    const float q = fu * fu + b0m1_;
    float xu = std::copysign(std::fabs(z0_), fu) / std::sqrt(std::max(q, 1e-30f));
    xu = std::clamp(xu, x0_, x1_);
    // 2. Pick y uniformly in the projected height h = y / sqrt(d^2 + y^2) along that line
    // (d^2 = xu^2 + z0^2; y = h d / sqrt(1 - h^2) as one root of a quotient).
    const float dist2 = xu * xu + z0_ * z0_;
    const float h0 = y0_ / std::sqrt(dist2 + y0_ * y0_);
    const float h1 = y1_ / std::sqrt(dist2 + y1_ * y1_);
    const float hv = h0 + u.y * (h1 - h0);
    const float hv2 = hv * hv;
    const float yv = hv2 < 1.0f - 1e-6f ? hv * std::sqrt(dist2 / (1.0f - hv2)) : y1_;
    return o_ + x_ * xu + y_ * std::clamp(yv, y0_, y1_) + z_ * z0_;
  }

 private:
  // a + b for the angles a = atan2(sa, ca), b = atan2(sb, cb) in [0, pi] (sa, sb >= 0): the
  // argument of (ca + i sa)(cb + i sb), mapped to [0, 2 pi).
  static float angle_sum(float ca, float sa, float cb, float sb) {
    const float a = atan2_fast(ca * sb + sa * cb, ca * cb - sa * sb);
    return a < 0.0f ? a + 2.0f * kPi : a;
  }

  Vec3f o_, x_, y_, z_;
  float x0_, y0_, z0_, x1_, y1_;
  float b0_, b1_, b0m1_, k_, solid_angle_;
};

}  // namespace gdpt::lights
