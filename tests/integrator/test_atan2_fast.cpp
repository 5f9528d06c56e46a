// atan2_fast against std::atan2 in double: every quadrant, the axes, tiny and huge arguments.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/atan2_fast.h"

using gdpt::atan2_fast;

TEST(Atan2Fast, MatchesStdAtan2EverywhereWithin4e7) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> angle(-3.14159f, 3.14159f);
  std::uniform_real_distribution<float> log_r(-20.0f, 20.0f);
  double worst = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const float t = angle(rng), r = std::exp(log_r(rng));
    const float x = r * std::cos(t), y = r * std::sin(t);
    const double err = std::fabs(double(atan2_fast(y, x)) - std::atan2(double(y), double(x)));
    worst = std::max(worst, err);
  }
  EXPECT_LT(worst, 4e-7);  // ~1.3 ulp at pi; glibc atan2f is within 1 ulp
}

TEST(Atan2Fast, AxesAndSignsAsStdAtan2) {
  for (float y : {0.0f, 1.0f, -1.0f, 1e-30f, -1e30f})
    for (float x : {1.0f, -1.0f, 1e-30f, -1e30f, 2.5f})
      EXPECT_NEAR(atan2_fast(y, x), std::atan2(y, x), 3e-7) << y << " " << x;
  EXPECT_EQ(atan2_fast(0.0f, 0.0f), 0.0f);
  EXPECT_NEAR(atan2_fast(1.0f, 0.0f), 0.5 * M_PI, 3e-7);
  EXPECT_NEAR(atan2_fast(-1.0f, 0.0f), -0.5 * M_PI, 3e-7);
  EXPECT_NEAR(atan2_fast(1.0f, 1.0f), 0.25 * M_PI, 3e-7);
}
