// The pixel filter's sampled positions follow Cycles' filter profiles: a chi-square test of a
// histogram of positions against the profile's integral over each bin, computed here by Simpson's
// rule from Cycles' definitions (not from the sampler's closed-form CDF); the box of width 1 is
// the plain jitter, bit for bit; bad widths are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "render/pixel_filter.h"

namespace gdpt {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Cycles' profiles (scene/film.cpp) of width w, as functions of the offset x from the centre, and
// their supports: box [-w/2, w/2], Gaussian evaluated at width 3w, Blackman-Harris at width 2w.
double profile(PixelFilterType type, double w, double x) {
  switch (type) {
    case PixelFilterType::Gaussian: {
      const double v = x * 6.0 / (3.0 * w);
      return std::exp(-2.0 * v * v);
    }
    case PixelFilterType::BlackmanHarris: {
      const double v = 2.0 * kPi * (x / (2.0 * w) + 0.5);
      return 0.35875 - 0.48829 * std::cos(v) + 0.14128 * std::cos(2.0 * v) -
             0.01168 * std::cos(3.0 * v);
    }
    case PixelFilterType::Box:
      break;
  }
  return 1.0;
}

double radius_of(PixelFilterType type, double w) {
  return type == PixelFilterType::Gaussian         ? 1.5 * w
         : type == PixelFilterType::BlackmanHarris ? w
                                                   : 0.5 * w;
}

double simpson(PixelFilterType type, double w, double a, double b) {
  constexpr int n = 200;  // even
  const double h = (b - a) / n;
  double s = profile(type, w, a) + profile(type, w, b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * profile(type, w, a + i * h);
  return s * h / 3.0;
}

// Chi-square quantile at p = 0.001 (Wilson-Hilferty).
double chi2_critical(int dof) {
  const double k = dof, z = 3.090;
  const double c = 1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k));
  return k * c * c * c;
}

struct ChiSquare {
  double statistic = 0.0;
  int dof = 0;
  int outside = 0;  // samples outside the support
};

// Histogram of one axis of `filter`'s positions (relative to the pixel centre) over the support in
// `bins` bins against the profile's integrals; bins expecting fewer than 5 samples are merged
// with the next ones.
ChiSquare chi_square(const PixelFilter& filter, PixelFilterType type, double w, int axis,
                     int samples, int bins) {
  const double r = radius_of(type, w);
  std::vector<double> observed(size_t(bins), 0.0), expected(size_t(bins), 0.0);
  double total = 0.0;
  for (int b = 0; b < bins; ++b) {
    expected[size_t(b)] = simpson(type, w, -r + 2.0 * r * b / bins, -r + 2.0 * r * (b + 1) / bins);
    total += expected[size_t(b)];
  }
  for (double& e : expected) e *= double(samples) / total;
  std::mt19937 rng(12345u + uint32_t(axis));
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  ChiSquare c;
  for (int i = 0; i < samples; ++i) {
    const Vec2f u(uni(rng), uni(rng));
    const Vec2f p = filter.position(u);
    const double x = double(axis == 0 ? p.x : p.y) - 0.5;
    const int b = int(std::floor((x + r) / (2.0 * r) * bins));
    if (b < 0 || b >= bins) {
      // The end points of the support itself round either way.
      if (std::fabs(std::fabs(x) - r) > 1e-5) ++c.outside;
      observed[size_t(std::clamp(b, 0, bins - 1))] += 1.0;
      continue;
    }
    observed[size_t(b)] += 1.0;
  }
  double o = 0.0, e = 0.0;
  int groups = 0;
  for (int b = 0; b < bins; ++b) {
    o += observed[size_t(b)];
    e += expected[size_t(b)];
    if (e < 5.0 && b + 1 < bins) continue;
    c.statistic += (o - e) * (o - e) / e;
    ++groups;
    o = e = 0.0;
  }
  c.dof = groups - 1;
  return c;
}

struct Case {
  PixelFilterType type;
  float width;
  const char* name;
};

TEST(PixelFilter, PositionsFollowTheFilterProfile) {
  const Case cases[] = {{PixelFilterType::BlackmanHarris, 1.5f, "blackman-harris 1.5"},
                        {PixelFilterType::BlackmanHarris, 0.7f, "blackman-harris 0.7"},
                        {PixelFilterType::Gaussian, 1.5f, "gaussian 1.5"},
                        {PixelFilterType::Gaussian, 3.0f, "gaussian 3"},
                        {PixelFilterType::Box, 1.0f, "box 1"},
                        {PixelFilterType::Box, 2.5f, "box 2.5"}};
  for (const Case& k : cases) {
    const PixelFilter filter(k.type, k.width);
    EXPECT_FLOAT_EQ(filter.radius(), float(radius_of(k.type, k.width))) << k.name;
    for (int axis = 0; axis < 2; ++axis) {
      const ChiSquare c = chi_square(filter, k.type, k.width, axis, 1 << 20, 64);
      std::printf("[%s axis %d] chi2 %.1f, dof %d, critical %.1f\n", k.name, axis, c.statistic,
                  c.dof, chi2_critical(c.dof));
      EXPECT_EQ(c.outside, 0) << k.name;
      EXPECT_GT(c.dof, 20) << k.name;
      EXPECT_LT(c.statistic, chi2_critical(c.dof)) << k.name << " axis " << axis;
    }
  }
}

// The box of width 1 is the unfiltered jitter, so images rendered with it are unchanged.
TEST(PixelFilter, UnitBoxIsTheJitter) {
  const PixelFilter box;
  const PixelFilter box1(PixelFilterType::Box, 1.0f);
  std::mt19937 rng(7u);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (int i = 0; i < 10000; ++i) {
    const Vec2f u(uni(rng), uni(rng));
    ASSERT_EQ(box.position(u).x, u.x);
    ASSERT_EQ(box1.position(u).y, u.y);
    const Vec2f r = box1.raster(37, 12, u);
    ASSERT_EQ(r.x, 37.0f + u.x);
    ASSERT_EQ(r.y, 12.0f + u.y);
  }
}

// Symmetric about the pixel centre, within the support, monotonic in u.
TEST(PixelFilter, TableIsSymmetricAndMonotonic) {
  for (PixelFilterType t : {PixelFilterType::Gaussian, PixelFilterType::BlackmanHarris}) {
    const PixelFilter f(t, 1.5f);
    float prev = -1e9f;
    for (int i = 0; i <= 4096; ++i) {
      const float u = float(i) / 4096.0f;
      const float x = f.position(Vec2f(u, u)).x;
      ASSERT_GE(x, prev);
      prev = x;
      ASSERT_GE(x, 0.5f - f.radius() - 1e-6f);
      ASSERT_LE(x, 0.5f + f.radius() + 1e-6f);
      // Within a cell of the 1024-cell table (the far tails' cells round unevenly).
      if (i == 0 || i == 4096) continue;
      ASSERT_NEAR(x - 0.5f, 0.5f - f.position(Vec2f(1.0f - u, 0.0f)).x, 2.0f * f.radius() / 1024)
          << u;
    }
  }
}

TEST(PixelFilter, RefusesBadWidths) {
  EXPECT_THROW(PixelFilter(PixelFilterType::Box, 0.0f), std::invalid_argument);
  EXPECT_THROW(PixelFilter(PixelFilterType::Gaussian, -1.0f), std::invalid_argument);
  EXPECT_THROW(PixelFilter(PixelFilterType::BlackmanHarris, std::nanf("")), std::invalid_argument);
  EXPECT_THROW(PixelFilter(PixelFilterType::BlackmanHarris, INFINITY), std::invalid_argument);
}

}  // namespace
}  // namespace gdpt
