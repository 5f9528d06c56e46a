// Chi-square goodness-of-fit of a direction sampler against its density, as in Mitsuba's and
// Nori's BSDF test suites: sampled directions are binned over (cos theta, phi), the density is
// integrated over every bin with adaptive Simpson quadrature, bins expecting fewer than 5
// samples are pooled, and the chi-square statistic gives a p-value.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "core/vec.h"
#include "testing/statistics.h"

namespace gdpt::test {

// Small deterministic generator (PCG32) so that every test run sees the same numbers.
class Pcg32 {
 public:
  explicit Pcg32(uint64_t seed) : state_(0), inc_((seed << 1u) | 1u) {
    next();
    state_ += 0x853c49e6748fea9bULL + seed;
    next();
  }
  uint32_t next() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  // Uniform in [0, 1).
  float uniform() { return float(next() >> 8) * (1.0f / 16777216.0f); }

 private:
  uint64_t state_, inc_;
};

inline Vec3f direction(double cos_theta, double phi) {
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  return Vec3f(float(sin_theta * std::cos(phi)), float(sin_theta * std::sin(phi)),
               float(cos_theta));
}

// Adaptive 2-D Simpson on [x0, x1] x [y0, y1].
class Integrator2D {
 public:
  explicit Integrator2D(std::function<double(double, double)> f) : f_(std::move(f)) {}

  double integrate(double x0, double x1, double y0, double y1, double eps, int min_depth = 2,
                   int max_depth = 8) {
    return rec(x0, x1, y0, y1, simpson(x0, x1, y0, y1), eps, 0, min_depth, max_depth);
  }

 private:
  double simpson(double x0, double x1, double y0, double y1) {
    static const double w[3] = {1.0, 4.0, 1.0};
    double sum = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        sum += w[i] * w[j] * f_(x0 + (x1 - x0) * 0.5 * i, y0 + (y1 - y0) * 0.5 * j);
    return sum * (x1 - x0) * (y1 - y0) / 36.0;
  }
  double rec(double x0, double x1, double y0, double y1, double whole, double eps, int depth,
             int min_depth, int max_depth) {
    const double xm = 0.5 * (x0 + x1), ym = 0.5 * (y0 + y1);
    const double q[4] = {simpson(x0, xm, y0, ym), simpson(xm, x1, y0, ym), simpson(x0, xm, ym, y1),
                         simpson(xm, x1, ym, y1)};
    const double parts = q[0] + q[1] + q[2] + q[3];
    // Absolute tolerance for near-empty regions, relative (1e-4) where the density has mass:
    // the expected counts then carry errors far below their Poisson noise.
    const double tol = 15.0 * std::max(eps, 1e-4 * std::fabs(parts));
    if (depth >= max_depth || (depth >= min_depth && std::fabs(parts - whole) <= tol))
      return parts + (parts - whole) / 15.0;
    return rec(x0, xm, y0, ym, q[0], eps * 0.25, depth + 1, min_depth, max_depth) +
           rec(xm, x1, y0, ym, q[1], eps * 0.25, depth + 1, min_depth, max_depth) +
           rec(x0, xm, ym, y1, q[2], eps * 0.25, depth + 1, min_depth, max_depth) +
           rec(xm, x1, ym, y1, q[3], eps * 0.25, depth + 1, min_depth, max_depth);
  }
  std::function<double(double, double)> f_;
};

// Integral over the upper hemisphere of f(direction) d omega, by adaptive quadrature; the polar
// range is split finely near the pole, where narrow lobes peak.
inline double hemisphere_integral(const std::function<double(Vec3f)>& f) {
  Integrator2D integ([&](double theta, double phi) {
    return f(direction(std::cos(theta), phi)) * std::sin(theta);
  });
  const double edges[] = {0.0, 0.002, 0.01, 0.03, 0.1, 0.3, 0.7, 1.1, M_PI / 2};
  double sum = 0.0;
  for (size_t i = 0; i + 1 < std::size(edges); ++i)
    for (int k = 0; k < 8; ++k)
      sum += integ.integrate(edges[i], edges[i + 1], k * M_PI / 4, (k + 1) * M_PI / 4, 1e-9, 3, 10);
  return sum;
}

struct Chi2Result {
  double p_value = 0.0;
  double chi2 = 0.0;
  int dof = 0;
  double pdf_mass = 0.0;      // integral of the density over the sphere
  double sampled_mass = 0.0;  // fraction of samples that produced a (non-delta) direction
  std::string message;
};

// `sample(rng)` returns a direction, or nothing for failed / delta samples.
// `pdf(w)` is the solid-angle density of the non-delta samples.
inline Chi2Result chi2_test(const std::function<std::optional<Vec3f>(Pcg32&)>& sample,
                            const std::function<double(Vec3f)>& pdf, int n_samples, uint64_t seed,
                            int res_theta = 16, int res_phi = 32) {
  const int bins = res_theta * res_phi;
  std::vector<double> observed(size_t(bins), 0.0), expected(size_t(bins), 0.0);

  // --- Histogram of samples over (cos theta in [-1, 1], phi in [0, 2 pi)).
  Pcg32 rng(seed);
  int valid = 0;
  for (int i = 0; i < n_samples; ++i) {
    const std::optional<Vec3f> w = sample(rng);
    if (!w) continue;
    ++valid;
    const double z = std::clamp(double(w->z), -1.0, 1.0);
    double phi = std::atan2(double(w->y), double(w->x));
    if (phi < 0.0) phi += 2.0 * M_PI;
    const int it = std::min(res_theta - 1, int((z + 1.0) * 0.5 * res_theta));
    const int ip = std::min(res_phi - 1, int(phi / (2.0 * M_PI) * res_phi));
    observed[size_t(it * res_phi + ip)] += 1.0;
  }

  // --- Expected counts: the density integrated over each bin (d omega = d cos d phi).
  // Integrated over (theta, phi) with the sin(theta) Jacobian rather than over cos(theta):
  // peaks at the poles (normal incidence) stay resolvable.
  Integrator2D integ([&](double theta, double phi) {
    return pdf(direction(std::cos(theta), phi)) * std::sin(theta);
  });
  double mass = 0.0;
  for (int it = 0; it < res_theta; ++it) {
    const double z0 = -1.0 + 2.0 * it / res_theta, z1 = -1.0 + 2.0 * (it + 1) / res_theta;
    for (int ip = 0; ip < res_phi; ++ip) {
      const double p0 = 2.0 * M_PI * ip / res_phi, p1 = 2.0 * M_PI * (ip + 1) / res_phi;
      const double m = integ.integrate(std::acos(z1), std::acos(z0), p0, p1, 1e-7);
      expected[size_t(it * res_phi + ip)] = m * n_samples;
      mass += m;
    }
  }

  // --- Chi-square with pooling of the low-expectation bins.
  Chi2Result r;
  r.pdf_mass = mass;
  r.sampled_mass = double(valid) / n_samples;
  double pooled_obs = 0.0, pooled_exp = 0.0;
  int terms = 0;
  for (int b = 0; b < bins; ++b) {
    if (expected[size_t(b)] < 5.0) {
      pooled_obs += observed[size_t(b)];
      pooled_exp += expected[size_t(b)];
      continue;
    }
    const double d = observed[size_t(b)] - expected[size_t(b)];
    r.chi2 += d * d / expected[size_t(b)];
    ++terms;
  }
  if (pooled_exp >= 5.0) {
    const double d = pooled_obs - pooled_exp;
    r.chi2 += d * d / pooled_exp;
    ++terms;
  } else if (pooled_obs > pooled_exp + 5.0 * std::sqrt(pooled_exp + 1.0)) {
    r.message = "samples fall where the density is ~0 (" + std::to_string(pooled_obs) +
                " observed, " + std::to_string(pooled_exp) + " expected)";
    r.p_value = 0.0;
    return r;
  }
  // The samples' total is not fixed (failed samples), so every term is a free Poisson count.
  r.dof = std::max(1, terms);
  r.p_value = chi2_p_value(r.chi2, r.dof);
  return r;
}

}  // namespace gdpt::test
