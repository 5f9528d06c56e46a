// Adaptive sampling (integrators/adaptive_sampling.h): a stopped pixel holds exactly what a
// render of its sample count holds, pixels stop only below the noise threshold, the noisy ones
// take the samples, and at an equal number of pixel-samples the error against a converged
// reference is lower than a uniform render's.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <vector>

#include "integrators/adaptive_sampling.h"
#include "integrators/render_session.h"
#include "testing/gradient_scenes.h"

namespace gdpt {
namespace {

using gradient_test::make_scene;
using gradient_test::SceneKind;

// A Cornell box with a rough glass sphere: the light seen through the sphere is rare, bright
// paths (noisy pixels), the walls are smooth (pixels that converge early).
Scene glass_box(int res) {
  return make_scene(SceneKind::CornellGlass, res, 0.2f);
}

RenderSettings adaptive(RenderSettings::Mode mode, int spp, float threshold, uint32_t seed = 1) {
  RenderSettings s = gradient_test::settings(mode, spp, seed);
  s.samples_per_pass = 1;
  s.adaptive_threshold = threshold;
  return s;
}

struct Rendered {
  std::vector<uint32_t> counts;
  std::vector<double> variance, luminance, noise;
  gradient_test::Passes passes;
};

Rendered render(const Scene& scene, const RenderSettings& s) {
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  session.render(nullptr, cancel);
  const Film& f = session.film();
  Rendered r;
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x) {
      const size_t i = size_t(y) * f.width() + x;
      r.counts.push_back(f.samples(x, y));
      r.variance.push_back(f.pixel_variance(i));
      r.luminance.push_back(f.pixel_luminance(i));
      r.noise.push_back(adaptive_noise(f, i));
    }
  r.passes = gradient_test::read_film(f);
  return r;
}

TEST(AdaptiveSampling, MinSamples) {
  RenderSettings s;
  s.samples = 64;
  EXPECT_EQ(adaptive_min_samples(s), 16);
  s.samples = 30;  // a quarter rounded up to even
  EXPECT_EQ(adaptive_min_samples(s), 8);
  s.samples = 6;
  EXPECT_EQ(adaptive_min_samples(s), 4);
  s.samples = 3;
  EXPECT_EQ(adaptive_min_samples(s), 3);
  s.samples = 1 << 24;  // a time-limited render's count
  EXPECT_EQ(adaptive_min_samples(s), 64);
  s.samples = 64;
  s.adaptive_min_samples = 10;
  EXPECT_EQ(adaptive_min_samples(s), 10);
  s.adaptive_min_samples = 5;
  EXPECT_EQ(adaptive_min_samples(s), 5);
  s.feature_passes = true;  // pixels stop at even counts only
  EXPECT_EQ(adaptive_min_samples(s), 6);
}

// The mask on a film of known sums: one noisy pixel keeps its 3x3 neighbourhood sampling (clipped
// at the border), a pixel that stopped stays stopped, black noiseless pixels stop.
TEST(AdaptiveSampling, MaskKeepsTheNoisyPixelsNeighbourhood) {
  Film film(6, 5, true);                              // PT layout: the primal alone
  auto set = [&](int x, int y, double a, double b) {  // two samples of luminance-neutral grey
    Film::Accumulator& p = film.pixel(x, y);
    for (int c = 0; c < 3; ++c) p.primal[c] = a + b;
    p.primal2 = a * a + b * b;
    film.add_sample_count(x, y, 2);
  };
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 6; ++x) {
      if (x == 0 && y == 0)
        set(x, y, 0.0, 0.0);  // black: converged, not 0 / 0
      else if (x == 4 && y == 2)
        set(x, y, 0.0, 2.0);  // the mean's standard deviation 1, luminance 1: noise ~1
      else
        set(x, y, 0.5, 0.5);  // no noise
    }
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 6; ++x) {
      if (!(x == 4 && y == 2)) {
        EXPECT_EQ(adaptive_noise(film, size_t(y) * 6 + x), 0.0);
      }
    }
  EXPECT_NEAR(adaptive_noise(film, 2 * 6 + 4), 1.0, 1e-3);
  std::vector<uint8_t> mask;
  EXPECT_EQ(update_sampling_mask(film, 0.5f, mask), 9u);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 6; ++x)
      EXPECT_EQ(mask[size_t(y) * 6 + x], x >= 3 && x <= 5 && y >= 1 && y <= 3) << x << "," << y;
  // A threshold above every pixel's noise stops them all, and they stay stopped.
  EXPECT_EQ(update_sampling_mask(film, 2.0f, mask), 0u);
  EXPECT_EQ(update_sampling_mask(film, 0.5f, mask), 0u);  // the noisy pixel stopped at 2.0
  mask.clear();                                           // a new render: every pixel samples again
  EXPECT_EQ(update_sampling_mask(film, 0.5f, mask), 9u);
  for (int c = 0; c < 3; ++c) film.pixel(4, 2).primal[c] = 2.0;  // now two samples of 1
  film.pixel(4, 2).primal2 = 2.0;
  EXPECT_EQ(update_sampling_mask(film, 0.5f, mask), 0u);
}

// Each pixel's sums are those of a uniform render of its own sample count, bit for bit (its
// samples are the prefix of its sample indices); the counts span min .. samples; every pixel
// that stopped early is below the threshold.
TEST(AdaptiveSampling, StoppedPixelsHoldARenderOfTheirCount) {
  const Scene scene = glass_box(20);
  for (auto mode : {RenderSettings::Mode::GPT, RenderSettings::Mode::PT}) {
    const RenderSettings s = adaptive(mode, 24, 0.05f);
    const Rendered a = render(scene, s);
    const uint32_t lo = *std::min_element(a.counts.begin(), a.counts.end());
    const uint32_t hi = *std::max_element(a.counts.begin(), a.counts.end());
    EXPECT_EQ(lo, uint32_t(adaptive_min_samples(s)));
    EXPECT_EQ(hi, 24u);
    std::map<uint32_t, int> per_count;
    for (uint32_t c : a.counts) ++per_count[c];
    ASSERT_GE(per_count.size(), 3u) << "the threshold should stop pixels at several counts";
    for (const auto& [count, pixels] : per_count) {
      RenderSettings u = s;
      u.adaptive_threshold = 0.0f;
      u.samples = int(count);
      const Rendered uniform = render(scene, u);
      for (size_t i = 0; i < a.counts.size(); ++i) {
        if (a.counts[i] != count) continue;
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(a.passes.primal[3 * i + c], uniform.passes.primal[3 * i + c]) << i;
        ASSERT_EQ(a.variance[i], uniform.variance[i]) << i;  // its four gradient halves' too
        if (count < 24u) {
          EXPECT_LT(a.noise[i], s.adaptive_threshold) << i;
        }
      }
    }
  }
}

// With the feature passes a pixel stops only after an even number of samples: its halves (even
// and odd sample indices) stay equal.
TEST(AdaptiveSampling, FeaturePassesStopAtEvenCounts) {
  for (int min_samples : {0, 5}) {  // 5: the first judgement at 6
    RenderSettings s = adaptive(RenderSettings::Mode::GPT, 21, 0.05f);
    s.feature_passes = true;
    s.adaptive_min_samples = min_samples;
    s.samples_per_pass = 8;
    const Rendered a = render(glass_box(16), s);
    int below = 0;
    for (uint32_t c : a.counts) {
      EXPECT_TRUE(c % 2 == 0 || c == 21u) << c;
      below += c < 21u;
    }
    EXPECT_GT(below, 0) << min_samples;
  }
}

// The rare bright paths through the glass keep their pixels sampling; the smooth walls stop
// early. Pixels ranked by the noise a uniform render of the minimum count sees: the noisiest
// tenth against the quieter half of the lit pixels.
TEST(AdaptiveSampling, NoisyPixelsTakeTheSamples) {
  const Scene scene = glass_box(24);
  const RenderSettings s = adaptive(RenderSettings::Mode::GPT, 64, 0.07f);
  const Rendered a = render(scene, s);
  RenderSettings u = s;
  u.adaptive_threshold = 0.0f;
  u.samples = adaptive_min_samples(s);
  const Rendered probe = render(scene, u);
  std::vector<size_t> lit;
  for (size_t i = 0; i < a.counts.size(); ++i)
    if (probe.luminance[i] > 0.0) lit.push_back(i);
  std::sort(lit.begin(), lit.end(),
            [&](size_t x, size_t y) { return probe.noise[x] < probe.noise[y]; });
  const size_t tenth = lit.size() / 10, half = lit.size() / 2;
  double quiet = 0.0, noisy = 0.0, total = 0.0;
  for (size_t k = 0; k < half; ++k) quiet += a.counts[lit[k]];
  for (size_t k = 0; k < tenth; ++k) noisy += a.counts[lit[lit.size() - 1 - k]];
  for (uint32_t c : a.counts) total += c;
  quiet /= double(half), noisy /= double(tenth);
  std::printf("mean samples: quieter half %.1f, noisiest tenth %.1f, all %.1f (of %d)\n", quiet,
              noisy, total / double(a.counts.size()), s.samples);
  EXPECT_GT(noisy, 1.5 * quiet);
  EXPECT_LT(total, 0.8 * double(s.samples) * double(a.counts.size()));
}

// The oracle: a converged reference. At the same total of pixel-samples, the adaptive render's
// primal and L2 reconstruction have lower relMSE than a uniform render's (mean over seeds).
TEST(AdaptiveSampling, LowerErrorAtEqualPixelSamples) {
  const Scene scene = glass_box(24);
  RenderSettings rs = gradient_test::settings(RenderSettings::Mode::GPT, 2048, 99);
  const gradient_test::Passes ref = gradient_test::render(scene, rs);
  const std::vector<float> ref_l2 = gradient_test::reconstruct_l2(ref);
  double adaptive_primal = 0.0, uniform_primal = 0.0, adaptive_l2 = 0.0, uniform_l2 = 0.0;
  const int seeds = 4;
  for (int seed = 1; seed <= seeds; ++seed) {
    const RenderSettings s = adaptive(RenderSettings::Mode::GPT, 128, 0.04f, uint32_t(seed));
    const Rendered a = render(scene, s);
    double total = 0.0;
    for (uint32_t c : a.counts) total += c;
    RenderSettings u = s;
    u.adaptive_threshold = 0.0f;
    u.samples = int(std::ceil(total / double(a.counts.size())));  // at least as many
    const Rendered b = render(scene, u);
    adaptive_primal += gradient_test::rel_mse(a.passes.primal, ref.primal);
    uniform_primal += gradient_test::rel_mse(b.passes.primal, ref.primal);
    adaptive_l2 += gradient_test::rel_mse(gradient_test::reconstruct_l2(a.passes), ref_l2);
    uniform_l2 += gradient_test::rel_mse(gradient_test::reconstruct_l2(b.passes), ref_l2);
    std::printf("seed %d: adaptive %.1f spp on average, uniform %d; relMSE primal %.4g / %.4g\n",
                seed, total / double(a.counts.size()), u.samples,
                gradient_test::rel_mse(a.passes.primal, ref.primal),
                gradient_test::rel_mse(b.passes.primal, ref.primal));
  }
  std::printf("relMSE primal: adaptive %.4g, uniform %.4g; L2: adaptive %.4g, uniform %.4g\n",
              adaptive_primal / seeds, uniform_primal / seeds, adaptive_l2 / seeds,
              uniform_l2 / seeds);
  EXPECT_LT(adaptive_primal, uniform_primal);
  EXPECT_LT(adaptive_l2, uniform_l2);
}

// A cancel keeps the finished passes, pixels stopped or not; a time limit ends the render with
// each pixel's count between the minimum and the samples.
TEST(AdaptiveSampling, CancelAndTimeLimitKeepTheSamplesDone) {
  const Scene scene = glass_box(24);
  RenderSettings s = adaptive(RenderSettings::Mode::GPT, 1 << 20, 0.05f);
  s.adaptive_min_samples = 8;
  s.samples_per_pass = 64;  // passes end at the minimum, then every 4 samples
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  int passes = 0;
  session.render(
      [&](const RenderProgress& p) {
        if (++passes == 6) cancel.store(true);
        EXPECT_EQ(uint32_t(p.samples_done), session.film().max_samples());
      },
      cancel);
  const Film& f = session.film();
  EXPECT_EQ(f.min_samples(), 8u);
  EXPECT_EQ(f.max_samples(), 8u + 5u * 4u);  // the minimum's pass, then five passes of 4
  std::vector<float> primal(3 * f.pixel_count());
  f.primal_rgb(primal.data());
  double sum = 0.0;
  for (float v : primal) sum += v;
  EXPECT_GT(sum, 0.0);

  s.time_limit = 0.3;
  const auto start = std::chrono::steady_clock::now();
  RenderSession timed(scene, s);
  std::atomic<bool> never{false};
  timed.render(nullptr, never);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 5.0);
  EXPECT_GE(timed.film().min_samples(), 1u);
  EXPECT_LT(timed.film().max_samples(), uint32_t(s.samples));
}

TEST(AdaptiveSampling, RefusesSplitFramesAndBadThresholds) {
  const Scene scene = glass_box(8);
  RenderSettings s = adaptive(RenderSettings::Mode::GPT, 8, 0.01f);
  s.sample_offset = 8;
  EXPECT_THROW(RenderSession(scene, s), std::invalid_argument);
  s.sample_offset = 0;
  s.frame_samples = 16;
  EXPECT_THROW(RenderSession(scene, s), std::invalid_argument);
  s.frame_samples = 0;
  s.adaptive_threshold = -1.0f;
  EXPECT_THROW(RenderSession(scene, s), std::invalid_argument);
  s.adaptive_threshold = 0.01f;
  s.adaptive_min_samples = -1;
  EXPECT_THROW(RenderSession(scene, s), std::invalid_argument);
}

}  // namespace
}  // namespace gdpt
