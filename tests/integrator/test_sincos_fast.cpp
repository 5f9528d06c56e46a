// sincos_fast against std::sin / std::cos in double: a dense sweep of [-4 pi, 4 pi], random
// arguments up to 1e5, and the exact multiples of pi / 2 (quadrant signs).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "integrator/math/sincos_fast.h"

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
