// sincos_fast against std::sin / std::cos in double: a dense sweep of [-4 pi, 4 pi], random
// arguments up to 1e5, and the exact multiples of pi / 2 (quadrant signs).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/sincos_fast.h"
#include "core/warp_disk.h"

using gdpt::sincos_fast;

namespace {

double worst_error(float x) {
  float s, c;
  sincos_fast(x, &s, &c);
  return std::max(std::fabs(double(s) - std::sin(double(x))),
                  std::fabs(double(c) - std::cos(double(x))));
}

}  // namespace

TEST(SincosFast, DenseSweepOfFourTurnsWithin2e7) {
  double worst = 0.0;
  for (int i = -2000000; i <= 2000000; ++i) worst = std::max(worst, worst_error(i * 6.2832e-6f));
  EXPECT_LT(worst, 2e-7);
}

TEST(SincosFast, RandomArgumentsUpTo1e5Within2e7) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> arg(-1e5f, 1e5f);
  double worst = 0.0;
  for (int i = 0; i < 1000000; ++i) worst = std::max(worst, worst_error(arg(rng)));
  EXPECT_LT(worst, 2e-7);
}

TEST(SincosFast, QuadrantsHaveTheRightSigns) {
  for (int k = -8; k <= 8; ++k) {
    const float x = float(k * M_PI / 2 + 0.3);  // inside quadrant k, away from the zeros
    float s, c;
    sincos_fast(x, &s, &c);
    EXPECT_NEAR(s, std::sin(double(x)), 2e-7) << k;
    EXPECT_NEAR(c, std::cos(double(x)), 2e-7) << k;
  }
  float s, c;
  sincos_fast(0.0f, &s, &c);
  EXPECT_EQ(s, 0.0f);
  EXPECT_EQ(c, 1.0f);
}

// The concentric map uses the polynomials without range reduction: against Shirley-Chiu's map in
// double over a 1024^2 grid of the square (both octant cases, both signs), and the centre.
TEST(SincosFast, ConcentricDiskMapMatchesTheExactMapWithin3e7) {
  double worst = 0.0;
  for (int i = 0; i < 1024; ++i)
    for (int j = 0; j < 1024; ++j) {
      const gdpt::Vec2f u{(float(i) + 0.37f) / 1024.0f, (float(j) + 0.61f) / 1024.0f};
      const gdpt::Vec2f d = gdpt::square_to_disk_concentric(u);
      const double a = 2.0 * double(u.x) - 1.0, b = 2.0 * double(u.y) - 1.0;
      const bool first = std::fabs(a) > std::fabs(b);
      const double r = first ? a : b;
      const double phi = first ? M_PI / 4 * (b / a) : M_PI / 2 - M_PI / 4 * (a / b);
      worst = std::max({worst, std::fabs(double(d.x) - r * std::cos(phi)),
                        std::fabs(double(d.y) - r * std::sin(phi))});
    }
  EXPECT_LT(worst, 3e-7);
  const gdpt::Vec2f centre = gdpt::square_to_disk_concentric({0.5f, 0.5f});
  EXPECT_EQ(centre.x, 0.0f);
  EXPECT_EQ(centre.y, 0.0f);
}
