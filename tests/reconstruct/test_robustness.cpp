// Missing data, degenerate sizes, dynamic range and argument checks.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "reconstruct/reconstruct.h"
#include "testing/test_images.h"

namespace gdpt {
namespace {

using test::exact_gradients;
using test::make_image;

constexpr ReconstructionNorm kSolvingNorms[] = {ReconstructionNorm::L2, ReconstructionNorm::L1,
                                                ReconstructionNorm::Weighted};

const char* name(ReconstructionNorm n) {
  switch (n) {
    case ReconstructionNorm::L2:
      return "L2";
    case ReconstructionNorm::L1:
      return "L1";
    case ReconstructionNorm::Weighted:
      return "Weighted";
    default:
      return "None";
  }
}

// Exact, consistent data: the true image makes every term zero, so every norm must return it
// (up to solver precision), whatever the size and whatever is missing.
struct Exact {
  int w, h;
  std::vector<float> truth, gx, gy, variance;
  Exact(int w_, int h_, float scale = 1.f) : w(w_), h(h_), truth(make_image(w_, h_, scale)) {
    exact_gradients(truth, w, h, gx, gy);
    variance.assign(truth.size(), 0.01f);
    // Non-uniform variances so that Weighted really is weighted.
    for (size_t i = 0; i < variance.size(); i += 7) variance[i] = 1.f;
  }
  ReconstructionInput input() const {
    return {w, h, truth.data(), gx.data(), gy.data(), variance.data(), nullptr};
  }
};

void expect_finite(const std::vector<float>& v) {
  for (float x : v) ASSERT_TRUE(std::isfinite(x));
}

// Max |a - b| relative to max |b|.
double max_relative(const std::vector<float>& a, const std::vector<float>& b) {
  double num = 0, den = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    num = std::max(num, std::abs(double(a[i]) - b[i]));
    den = std::max(den, std::abs(double(b[i])));
  }
  return num / den;
}

TEST(Robustness, DegenerateAndOddSizesRecoverExactData) {
  for (auto [w, h] :
       {std::pair{1, 37}, std::pair{53, 1}, std::pair{1, 1}, std::pair{2, 2}, std::pair{31, 17}}) {
    const Exact e(w, h);
    for (ReconstructionNorm norm : kSolvingNorms) {
      ReconstructionSettings s;
      s.norm = norm;
      const auto out = reconstruct(e.input(), s);
      ASSERT_EQ(out.size(), e.truth.size());
      EXPECT_LT(max_relative(out, e.truth), 1e-4) << w << "x" << h << " " << name(norm);
    }
  }
}

TEST(Robustness, ConstantImage) {
  const int w = 20, h = 13;
  std::vector<float> c(size_t(w) * h * 3, 0.75f), zero(c.size(), 0.f);
  ReconstructionInput in{w, h, c.data(), zero.data(), zero.data(), c.data(), nullptr};
  for (ReconstructionNorm norm : kSolvingNorms) {
    ReconstructionSettings s;
    s.norm = norm;
    const auto out = reconstruct(in, s);
    for (float v : out) ASSERT_NEAR(v, 0.75f, 1e-5f) << name(norm);
  }
}

// Values from 1e-3 to 1e3 in one image.
TEST(Robustness, MillionToOneDynamicRange) {
  Exact e(40, 30);
  for (size_t i = 0; i < e.truth.size(); ++i)
    e.truth[i] = float(std::pow(10.0, -3.0 + 6.0 * double(i % 97) / 96.0));
  exact_gradients(e.truth, e.w, e.h, e.gx, e.gy);
  for (ReconstructionNorm norm : kSolvingNorms) {
    ReconstructionSettings s;
    s.norm = norm;
    const auto out = reconstruct(e.input(), s);
    expect_finite(out);
    EXPECT_LT(max_relative(out, e.truth), 1e-4) << name(norm);
  }
}

// NaN / Inf anywhere are missing data: the rest of the exact data still pins the true image.
TEST(Robustness, NonFiniteInputsAreMissingData) {
  Exact e(33, 21);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  e.truth[3 * 40 + 1] = nan;  // primal of pixel 40
  e.truth[3 * 41] = -inf;
  e.gx[3 * 100 + 2] = inf;
  e.gy[3 * 200] = nan;
  e.variance[3 * 300 + 1] = nan;
  const auto clean = make_image(e.w, e.h);
  std::vector<float> emission(e.truth.size(), 0.f);
  emission[5] = nan;
  emission[8] = 0.5f;
  ReconstructionInput in = e.input();
  in.emission = emission.data();
  for (ReconstructionNorm norm : kSolvingNorms) {
    ReconstructionSettings s;
    s.norm = norm;
    s.weighted_tolerance = 1e-6;
    ReconstructionReport report;
    auto out = reconstruct(in, s, &report);
    expect_finite(out);
    EXPECT_EQ(report.missing_values, 4) << name(norm);
    out[8] -= 0.5f;  // emission is added where finite
    EXPECT_LT(max_relative(out, clean), 2e-4) << name(norm);
  }
  ReconstructionSettings none;
  none.norm = ReconstructionNorm::None;
  const auto out = reconstruct(in, none);
  expect_finite(out);
  EXPECT_EQ(out[3 * 40 + 1], 0.f);
  EXPECT_EQ(out[3 * 40], clean[3 * 40]);
  EXPECT_FLOAT_EQ(out[8], clean[8] + 0.5f);
}

TEST(Robustness, EverythingMissingGivesFiniteOutput) {
  const int w = 9, h = 7;
  std::vector<float> nan(size_t(w) * h * 3, std::numeric_limits<float>::quiet_NaN());
  ReconstructionInput in{w, h, nan.data(), nan.data(), nan.data(), nan.data(), nullptr};
  for (ReconstructionNorm norm : kSolvingNorms) {
    ReconstructionSettings s;
    s.norm = norm;
    const auto out = reconstruct(in, s);
    for (float v : out) ASSERT_EQ(v, 0.f) << name(norm);
  }
}

TEST(Robustness, EmissionIsAddedToTheSolution) {
  const Exact e(16, 12);
  std::vector<float> emission(e.truth.size());
  for (size_t i = 0; i < emission.size(); ++i) emission[i] = 0.01f * float(i % 13);
  ReconstructionInput in = e.input();
  ReconstructionSettings s;
  s.norm = ReconstructionNorm::L2;
  const auto without = reconstruct(in, s);
  in.emission = emission.data();
  const auto with = reconstruct(in, s);
  for (size_t i = 0; i < with.size(); ++i) ASSERT_FLOAT_EQ(with[i], without[i] + emission[i]);
}

TEST(Robustness, InvalidArgumentsThrow) {
  const Exact e(8, 8);
  ReconstructionSettings s;
  s.norm = ReconstructionNorm::L2;
  for (float alpha : {0.f, -1.f, std::numeric_limits<float>::quiet_NaN()}) {
    s.alpha = alpha;
    EXPECT_THROW(reconstruct(e.input(), s), std::invalid_argument) << alpha;
  }
  s.alpha = 0.2f;
  ReconstructionInput in = e.input();
  in.width = 0;
  EXPECT_THROW(reconstruct(in, s), std::invalid_argument);
  in = e.input();
  in.gradient_y = nullptr;
  EXPECT_THROW(reconstruct(in, s), std::invalid_argument);
  in = e.input();
  in.variance = nullptr;
  s.norm = ReconstructionNorm::Weighted;
  EXPECT_THROW(reconstruct(in, s), std::invalid_argument);
}

// Fixed row chunks and ordered reductions: the thread count does not change the result.
TEST(Robustness, SameResultOnOneAndTwoThreads) {
  const int w = 64, h = 50;
  auto truth = make_image(w, h);
  std::vector<float> gx, gy;
  exact_gradients(truth, w, h, gx, gy);
  const auto noise = test::zero_mean_noise(size_t(w) * h, 0.3f, 5);
  const auto primal = test::add(truth, noise);
  ReconstructionInput in{w, h, primal.data(), gx.data(), gy.data(), nullptr, nullptr};
  ReconstructionSettings s;
  s.norm = ReconstructionNorm::L1;
  s.threads = 1;
  const auto one = reconstruct(in, s);
  s.threads = 2;
  const auto two = reconstruct(in, s);
  EXPECT_EQ(one, two);
  // A warm start (from the L2 output, at another alpha) too.
  s.norm = ReconstructionNorm::L2;
  const auto start = reconstruct(in, s);
  in.initial = start.data();
  s.norm = ReconstructionNorm::L1;
  s.alpha = 0.3f;
  const auto warm_two = reconstruct(in, s);
  s.threads = 1;
  EXPECT_EQ(reconstruct(in, s), warm_two);
}

// A warm start with NaN / Inf in the start image (and in the inputs and emission) still gives a
// finite image near the truth: non-finite start values fall back to the primal's.
TEST(Robustness, NonFiniteWarmStartValues) {
  Exact e(33, 21);
  const auto clean = e.truth;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  e.truth[3 * 40 + 1] = nan;
  e.gx[3 * 100 + 2] = inf;
  std::vector<float> emission(clean.size(), 0.f);
  emission[5] = nan;
  std::vector<float> start = clean;
  start[3 * 7] = nan;
  start[3 * 300 + 2] = -inf;
  for (size_t i = 3 * 500; i < 3 * 520; ++i) start[i] = nan;
  ReconstructionInput in = e.input();
  in.emission = emission.data();
  in.initial = start.data();
  ReconstructionSettings s;
  s.norm = ReconstructionNorm::L1;
  ReconstructionReport report;
  const auto out = reconstruct(in, s, &report);
  expect_finite(out);
  EXPECT_EQ(report.missing_values, 2);
  EXPECT_LT(max_relative(out, clean), 2e-4);
}

}  // namespace
}  // namespace gdpt
