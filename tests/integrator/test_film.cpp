// Film read-out: means, variance of the mean, PT-mode gradients (forward differences of the primal
// means with zero last column / row), shift-failure fractions and pass commits.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <stdexcept>
#include <vector>

#include "render/film.h"

namespace gdpt {
namespace {

void add(Film& f, int x, int y, Spectrum primal, Spectrum emission = Spectrum(0.0f)) {
  Film::Accumulator& a = f.pixel(x, y);
  for (int c = 0; c < 3; ++c) {
    a.primal[c] += primal[c];
    a.emission[c] += emission[c];
  }
  const double l = luminance(primal);
  a.primal2 += l * l;
  f.add_sample_count(x, y);
}

// The feature passes' halves (core/sample_halves.h): A the first ceil(N / 2) points of the
// sequence, B the next ones, so N samples take exactly the first N points; past the split (a
// time-limited render that outran its estimate) further segments, the union a prefix whenever a
// segment is full.
TEST(Film, HalvesTakeConsecutiveSegmentsOfOneSequence) {
  EXPECT_EQ(half_split(0), 1u);
  EXPECT_EQ(half_split(1), 1u);
  EXPECT_EQ(half_split(29), 15u);
  EXPECT_EQ(half_split(30), 15u);
  for (uint32_t n : {1u, 2u, 7u, 29u, 30u, 64u}) {
    const uint32_t split = half_split(n);
    std::set<uint32_t> a, b;
    for (uint32_t s = 0; s < n; ++s) {
      (in_half_a(s) ? a : b).insert(half_sequence_index(s, split));
    }
    std::set<uint32_t> all = a;
    all.insert(b.begin(), b.end());
    ASSERT_EQ(all.size(), size_t(n)) << n;
    EXPECT_EQ(*all.rbegin(), n - 1) << n;       // distinct and below n: exactly 0 .. n - 1
    EXPECT_EQ(*a.rbegin(), a.size() - 1) << n;  // A: 0 .. |A| - 1
    if (!b.empty()) {
      EXPECT_EQ(*b.begin(), split) << n;  // B from the split on
    }
  }
  const uint32_t order[12] = {0, 3, 1, 4, 2, 5, 6, 9, 7, 10, 8, 11};
  for (uint32_t s = 0; s < 12; ++s) EXPECT_EQ(half_sequence_index(s, 3), order[s]) << s;
  Film film(4, 4, false);
  EXPECT_EQ(film.sequence_index(5), 5u);  // no halves: the sample's own index
  film.set_half_split(3);
  EXPECT_EQ(film.sequence_index(5), 5u);
  EXPECT_EQ(film.sequence_index(6), 6u);
  EXPECT_EQ(film.sequence_index(3), 4u);
}

TEST(Film, MeansAndVarianceOfTheMean) {
  Film f(2, 1);
  // Pixel 0: grey samples 1, 2, 3 -> mean 2, sample variance 1, variance of the mean 1/3.
  for (float v : {1.0f, 2.0f, 3.0f}) add(f, 0, 0, Spectrum(v), Spectrum(0.5f));
  add(f, 1, 0, Spectrum(4.0f, 0.0f, 0.0f));
  add(f, 1, 0, Spectrum(4.0f, 0.0f, 0.0f));
  std::vector<float> p(6), e(6), v(6);
  f.primal_rgb(p.data());
  f.emission_rgb(e.data());
  f.variance3(v.data());
  EXPECT_FLOAT_EQ(p[0], 2.0f);
  EXPECT_FLOAT_EQ(p[3], 4.0f);
  EXPECT_FLOAT_EQ(p[4], 0.0f);
  EXPECT_FLOAT_EQ(e[0], 0.5f);
  EXPECT_NEAR(v[0], 1.0f / 3.0f, 1e-6f);
  EXPECT_NEAR(v[3], 0.0f, 1e-6f);  // constant samples
  EXPECT_EQ(f.samples(0, 0), 3u);
  EXPECT_EQ(f.min_samples(), 2u);
}

TEST(Film, PrimalGradientsInPtMode) {
  Film f(3, 2);
  // I(x, y) = x + 10 y (row 0 at the bottom).
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) add(f, x, y, Spectrum(float(x + 10 * y)));
  f.set_gradients_from_primal(true);
  std::vector<float> dx(18), dy(18);
  f.gradient_x_rgb(dx.data());
  f.gradient_y_rgb(dy.data());
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      const size_t i = size_t(y * 3 + x) * 3;
      EXPECT_FLOAT_EQ(dx[i], x < 2 ? 1.0f : 0.0f);
      EXPECT_FLOAT_EQ(dy[i], y < 1 ? 10.0f : 0.0f);
    }
}

TEST(Film, EstimatedGradientsAndShiftFailures) {
  Film f(1, 1);
  Film::GradientAccumulator& a = f.gradients(0, 0);
  a.dx[1] = 3.0;
  a.dy[2] = -6.0;
  a.shift_attempts = 8.0;
  a.shift_failures = 2.0;
  f.add_sample_count(0, 0, 3);
  std::vector<float> dx(3), dy(3), sf(1);
  f.gradient_x_rgb(dx.data());
  f.gradient_y_rgb(dy.data());
  f.shift_failures(sf.data());
  EXPECT_FLOAT_EQ(dx[1], 1.0f);
  EXPECT_FLOAT_EQ(dy[2], -2.0f);
  EXPECT_FLOAT_EQ(sf[0], 0.25f);
}

TEST(Film, TakeRowsCommitsAndClearsThePass) {
  Film film(2, 2), pass(2, 2);
  add(film, 0, 0, Spectrum(1.0f));
  add(pass, 0, 0, Spectrum(3.0f));
  add(pass, 1, 1, Spectrum(5.0f));
  film.take_rows(pass, 0, 1);  // only row 0
  EXPECT_EQ(film.samples(0, 0), 2u);
  EXPECT_EQ(pass.samples(0, 0), 0u);
  EXPECT_EQ(pass.samples(1, 1), 1u);
  std::vector<float> p(12);
  film.primal_rgb(p.data());
  EXPECT_FLOAT_EQ(p[0], 2.0f);
  EXPECT_FLOAT_EQ(p[9], 0.0f);  // pixel (1, 1) not committed yet
}

// PT films hold no gradient accumulators: commits and read-outs work without them, and a pass
// film of the other layout is refused rather than read out of bounds. The layout is chosen at
// construction (as RenderSession does) or switched afterwards.
TEST(Film, PtFilmsCommitWithoutGradientAccumulators) {
  Film film(2, 1), pass(2, 1, true), gpt_pass(2, 1);
  EXPECT_FALSE(film.gradients_from_primal());
  EXPECT_TRUE(pass.gradients_from_primal());
  film.set_gradients_from_primal(true);
  add(pass, 1, 0, Spectrum(4.0f));
  film.take_rows(pass, 0, 1);
  std::vector<float> p(6), sf(2, -1.0f), dx(6);
  film.primal_rgb(p.data());
  film.shift_failures(sf.data());
  film.gradient_x_rgb(dx.data());
  EXPECT_FLOAT_EQ(p[3], 4.0f);
  EXPECT_FLOAT_EQ(sf[0], 0.0f);
  EXPECT_FLOAT_EQ(sf[1], 0.0f);
  EXPECT_FLOAT_EQ(dx[0], 4.0f);  // forward difference of the primal means (pixel 0 has none)
  EXPECT_THROW(film.take_rows(gpt_pass, 0, 1), std::logic_error);
}

// The gradients over the samples' halves: half-A sums kept only with the feature passes in a
// film that holds gradients; the parity is the global index's (sample_offset); read-out as
// gradient_x_rgb over each half's own samples, half B = the totals minus half A.
TEST(Film, GradientsOverTheSampleHalves) {
  Film f(2, 1);
  EXPECT_FALSE(f.has_half_gradients());  // no feature passes: no cost
  f.enable_feature_passes(true);
  ASSERT_TRUE(f.has_half_gradients());
  f.set_sample_offset(1);  // samples 1, 2, 3: A = {2}, B = {1, 3}
  EXPECT_EQ(f.half_a_gradients(0, 0, 1), nullptr);
  EXPECT_EQ(f.half_a_gradients(0, 0, 3), nullptr);
  ASSERT_NE(f.half_a_gradients(0, 0, 2), nullptr);
  // Pixel 0: G_right sums 6 (all), 1 (A); pixel 1: G_left sums 9 (all), 3 (A).
  f.gradients(0, 0).dx[0] = 6.0;
  f.half_a_gradients(0, 0, 2)->dx[0] = 1.0;
  f.gradients(1, 0).dx_left[0] = 9.0;
  f.half_a_gradients(1, 0, 2)->dx_left[0] = 3.0;
  f.add_sample_count(0, 0, 3);
  f.add_sample_count(1, 0, 3);
  using H = Film::SampleHalf;
  std::vector<float> all(6), a(6), b(6), ya(6);
  f.gradient_x_rgb(all.data());
  f.gradient_x_half_rgb(H::A, a.data());
  f.gradient_x_half_rgb(H::B, b.data());
  f.gradient_y_half_rgb(H::A, ya.data());
  EXPECT_FLOAT_EQ(all[0], 6.0f / 3.0f - 9.0f / 3.0f);
  EXPECT_FLOAT_EQ(a[0], 1.0f / 1.0f - 3.0f / 1.0f);
  EXPECT_FLOAT_EQ(b[0], 5.0f / 2.0f - 6.0f / 2.0f);
  EXPECT_FLOAT_EQ((a[0] + 2.0f * b[0]) / 3.0f, all[0]);
  EXPECT_FLOAT_EQ(a[3], 0.0f);  // the last column: pixel 1's G_right sums are 0
  EXPECT_FLOAT_EQ(ya[0], 0.0f);
  // Committed with the pass, cleared with the film.
  Film film(2, 1);
  film.enable_feature_passes(true);
  film.set_sample_offset(1);
  film.take_rows(f, 0, 1);
  film.gradient_x_half_rgb(H::A, a.data());
  EXPECT_FLOAT_EQ(a[0], -2.0f);
  EXPECT_EQ(f.half_a_gradients(0, 0, 2)->dx[0], 0.0);
  film.clear();
  film.add_sample_count(0, 0, 3);
  film.gradient_x_half_rgb(H::A, a.data());
  EXPECT_FLOAT_EQ(a[0], 0.0f);
  // Half B with no samples reads 0; a PT film keeps no half sums.
  Film one(1, 1);
  one.enable_feature_passes(true);
  one.add_sample_count(0, 0, 1);
  one.gradients(0, 0).dx[0] = 4.0;
  one.half_a_gradients(0, 0, 0)->dx[0] = 4.0;
  one.gradient_x_half_rgb(H::B, b.data());
  EXPECT_FLOAT_EQ(b[0], 0.0f);
  Film plain(1, 1);  // no half sums: refuses a pass that has them
  EXPECT_THROW(plain.take_rows(one, 0, 1), std::logic_error);
  one.set_gradients_from_primal(true);
  EXPECT_FALSE(one.has_half_gradients());
}

}  // namespace
}  // namespace gdpt
