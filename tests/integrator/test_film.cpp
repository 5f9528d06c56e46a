// Film read-out: means, variance of the mean, PT-mode gradients (forward differences of the primal
// means with zero last column / row), shift-failure fractions and pass commits.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace gdpt
