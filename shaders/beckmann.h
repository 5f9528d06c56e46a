// The Beckmann microfacet distribution, as Cycles 3.4's `microfacet_beckmann` (the Glossy, Glass
// and Refraction BSDFs' Beckmann option, and the Anisotropic BSDF's), in the local frame
// (normal = +z, an anisotropic lobe's tangent on +x).
//
//  ax, ay: Beckmann widths along x and y, Blender roughness^2 (as for GGX); equal: isotropic.
//  D(m) = exp(-(mx^2 / ax^2 + my^2 / ay^2) / mz^2) / (pi ax ay mz^4), integrates to 1 over
//         projected area.
//  G1(w): the masking of the BSDF value, Cycles 3.4's rational fit of the Smith term (Walter et
//         al. 2007, eq. 27): with b = 1 / (alpha_w tan), alpha_w = sqrt(ax^2 wx^2 + ay^2 wy^2) /
//         sqrt(wx^2 + wy^2) the width along w's azimuth (bsdf_beckmann_aniso_G1), 1 for
//         b >= 1.6, else (3.535 b + 2.181 b^2) / (1 + 2.276 b + 2.577 b^2).
//  smith_G1(w): the exact Smith masking 1 / (1 + Lambda), the normalisation of the visible normals.
//  sample_visible(wi, u): a normal of the distribution visible from wi (wi.z > 0): the slopes of
//         the configuration stretched by (ax, ay) (Heitz and d'Eon 2014) by inverting their CDFs
//         to double precision, so its density is exactly pdf_visible(wi, m) = smith_G1(wi)
//         max(0, wi.m) D(m) / wi.z. (Cycles 3.4 samples an anisotropic lobe with ax for both
//         widths while weighting by the anisotropic D, which biases its sampled light; the
//         BSDF modelled here is the one Cycles evaluates.)
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/vec.h"

namespace gdpt {

namespace beckmann_detail {

inline constexpr double kInvSqrtPi = 0.56418958354775628;
// Slopes of the stretched configuration beyond this carry less than 1e-35 of the mass.
inline constexpr double kSlopeBound = 9.0;

// Unnormalised CDF of the stretched visible slope x seen at tan theta = t, and its density:
//   integral_{-inf}^{x} (1 - s t) exp(-s^2) / sqrt(pi) ds = erfc(-x) / 2 + t exp(-x^2) / (2
//   sqrt(pi))
// for x <= 1 / t (beyond, the facets face away). t = 0: the Gaussian of the other slope.
inline std::pair<double, double> visible_slope_cdf(double x, double t) {
  const double g = std::exp(-x * x) * kInvSqrtPi;
  return {0.5 * std::erfc(-x) + 0.5 * t * g, (1.0 - x * t) * g};
}

inline double slope_upper_bound(double t) {
  return t * kSlopeBound > 1.0 ? 1.0 / t : kSlopeBound;
}

// The slope below which a fraction u of the visible slopes lie: Newton's method on the CDF,
// falling back to bisection whenever a step would leave the bracket.
inline double sample_visible_slope(double t, double u) {
  double lo = -kSlopeBound, hi = slope_upper_bound(t);
  const double target = u * visible_slope_cdf(hi, t).first;
  double x = std::min(0.0, hi) - 0.25;
  for (int i = 0; i < 100; ++i) {
    const auto [f, df] = visible_slope_cdf(x, t);
    (f > target ? hi : lo) = x;
    double next = df > 0.0 ? x - (f - target) / df : lo;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::fabs(next - x) < 1e-12 || hi - lo < 1e-12) return next;
    x = next;
  }
  return x;
}

}  // namespace beckmann_detail

struct Beckmann {
  float ax, ay;

  explicit Beckmann(float a) : ax(a), ay(a) {}
  Beckmann(float alpha_x, float alpha_y) : ax(alpha_x), ay(alpha_y) {}

  float D(Vec3f m) const {
    if (m.z <= 0.0f) return 0.0f;
    const float z2 = m.z * m.z;
    const float c2 = z2 / length_squared(m);
    // tan^2 / alpha^2 from the horizontal part: (1 - c^2) / c^2 cancels for near-normal m at
    // small widths.
    const float sx = m.x / ax, sy = m.y / ay;
    const float e = std::exp(-(sx * sx + sy * sy) / z2);
    return e > 0.0f ? e / (kPi * ax * ay * c2 * c2) : 0.0f;  // 0, not 0 / 0, at grazing m
  }

  float G1(Vec3f w) const {
    const float z = std::fabs(w.z);
    if (z == 0.0f) return 0.0f;
    const float px = ax * w.x, py = ay * w.y;
    const float inv_b = std::sqrt(px * px + py * py) / z;  // alpha_w tan theta
    if (inv_b < 0.625f) return 1.0f;
    // The fit multiplied through by inv_b^2, so grazing directions (inv_b -> inf) give 0.
    return (2.181f + 3.535f * inv_b) / (2.577f + (2.276f + inv_b) * inv_b);
  }

  float smith_G1(Vec3f w) const {
    const double t = stretched_tan(w);
    if (!std::isfinite(t)) return 0.0f;
    const double cdf =
        beckmann_detail::visible_slope_cdf(beckmann_detail::slope_upper_bound(t), t).first;
    return float(1.0 / cdf);
  }

  float pdf_visible(Vec3f wi, Vec3f m) const {
    const float cos_im = dot(wi, m);
    if (cos_im <= 0.0f || wi.z <= 0.0f) return 0.0f;
    return smith_G1(wi) * cos_im * D(m) / wi.z;
  }

  Vec3f sample_visible(Vec3f wi, Vec2f u) const {
    // wi stretched to the configuration of unit widths, where the distribution is isotropic.
    const double px = double(ax) * wi.x, py = double(ay) * wi.y;
    const double r = std::sqrt(px * px + py * py);
    const double cos_phi = r > 0.0 ? px / r : 1.0, sin_phi = r > 0.0 ? py / r : 0.0;
    const double t = stretched_tan(wi);
    // Slopes of the stretched configuration with wi in the x-z plane, rotated to wi's azimuth
    // and scaled back by the widths.
    const double sx = beckmann_detail::sample_visible_slope(t, u.x);
    const double sy = beckmann_detail::sample_visible_slope(0.0, u.y);
    const double x = ax * (cos_phi * sx - sin_phi * sy);
    const double y = ay * (sin_phi * sx + cos_phi * sy);
    const double inv_len = 1.0 / std::sqrt(1.0 + x * x + y * y);
    return Vec3f(float(-x * inv_len), float(-y * inv_len), float(inv_len));
  }

 private:
  // alpha_w tan theta of w: its tangent in the configuration stretched to unit widths.
  double stretched_tan(Vec3f w) const {
    const double px = double(ax) * w.x, py = double(ay) * w.y;
    return std::sqrt(px * px + py * py) / std::fabs(double(w.z));
  }
};

}  // namespace gdpt
