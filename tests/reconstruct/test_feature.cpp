// The Feature reconstruction (feature-guided filters chosen per pixel by a cross-half error
// estimate) on synthetic images with known truth: recovery, edges, the error estimate, missing
// data, determinism, gain over L1.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "reconstruct/candidate_selection.h"
#include "reconstruct/feature_buffers.h"
#include "reconstruct/feature_reconstruct.h"
#include "reconstruct/half_outliers.h"
#include "reconstruct/reconstruct.h"
#include "testing/feature_scene.h"

namespace gdpt {
namespace {

using test::FeatureScene;
using test::make_feature_scene;
using test::relative_mse;

double mse(const std::vector<float>& x, const std::vector<float>& truth) {
  double s = 0.0;
  for (size_t i = 0; i < x.size(); ++i) s += (double(x[i]) - truth[i]) * (double(x[i]) - truth[i]);
  return s / double(x.size());
}

// Box filter of (A + B) / 2 over a (2 r + 1)^2 window clipped to the image.
std::vector<float> box_of_mean(const FeatureScene& s, int r) {
  std::vector<float> out(s.primal.size());
  detail::box_filter(s.primal.data(), 3, s.w, s.h, r, out.data());
  return out;
}

// box_filter against the direct mean over the clipped window: several channels, a height that is
// not a whole number of row chunks, and a window taller than the image.
TEST(Feature, BoxFilterIsTheMeanOverTheClippedWindow) {
  const int w = 23, h = 19, channels = 2;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1.f, 4.f);
  std::vector<float> src(size_t(w) * h * channels), dst(src.size());
  for (float& v : src) v = u(rng);
  for (int r : {0, 1, 3, 25}) {
    detail::box_filter(src.data(), channels, w, h, r, dst.data());
    double worst = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < channels; ++c) {
          double sum = 0.0;
          int count = 0;
          for (int yy = std::max(0, y - r); yy <= std::min(h - 1, y + r); ++yy)
            for (int xx = std::max(0, x - r); xx <= std::min(w - 1, x + r); ++xx, ++count)
              sum += src[(size_t(yy) * w + xx) * channels + c];
          const double d = dst[(size_t(y) * w + x) * channels + c] - sum / count;
          worst = std::max(worst, std::fabs(d));
        }
    EXPECT_LT(worst, 1e-5) << "radius " << r;
  }
}

// The primal halves filtered alone (no gradients), as in PT mode.
FeatureReconstruction filter_primal(const FeatureScene& s, bool features = true) {
  return feature_filter(s.input(features), s.a.data(), s.b.data(), s.primal.data());
}

// Per pixel truth that follows the features (albedo and depth): within each surface the filters
// average many pixels, so the result must be far below the noise of the halves' mean.
TEST(Feature, RecoversAnImageThatFollowsTheFeatures) {
  FeatureScene s = make_feature_scene(96, 64, 0.15f, 0.f, 11);
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.f, 0.15f);
  for (size_t i = 0; i < s.truth.size(); ++i) {
    s.truth[i] = 0.1f + 0.8f * s.albedo[i] + 0.05f * s.depth[i / 3];
    s.a[i] = s.truth[i] + noise(rng);
    s.b[i] = s.truth[i] + noise(rng);
    s.primal[i] = 0.5f * (s.a[i] + s.b[i]);
  }
  const FeatureReconstruction r = filter_primal(s);
  const double before = mse(s.primal, s.truth), after = mse(r.image, s.truth);
  std::printf("linear in features: MSE %.3g -> %.3g (ratio %.1f)\n", before, after, before / after);
  const double rb = relative_mse(s.primal, s.truth), ra = relative_mse(r.image, s.truth);
  std::printf("linear in features: relMSE %.3g -> %.3g (ratio %.1f)\n", rb, ra, rb / ra);
  EXPECT_LT(after, before / 20.0);
}

double band_rmse(const std::vector<float>& x, const FeatureScene& s,
                 bool (*in_band)(int, int, int, int)) {
  double sum = 0.0;
  size_t count = 0;
  for (int y = 0; y < s.h; ++y)
    for (int xx = 0; xx < s.w; ++xx) {
      if (!in_band(xx, y, s.w, s.h)) continue;
      for (int c = 0; c < 3; ++c) {
        const size_t i = 3 * (size_t(y) * s.w + xx) + c;
        sum += (double(x[i]) - s.truth[i]) * (double(x[i]) - s.truth[i]);
        ++count;
      }
    }
  return std::sqrt(sum / double(count));
}

// Within 2 pixels of the floor / wall boundary (a normal and albedo edge) and of the wall's
// painted stripe (an albedo edge), away from the box.
bool near_edge(int x, int y, int w, int h) {
  const float u = (x + 0.5f) / w;
  if (u > 0.5f) return false;
  for (float edge : {0.35f, 0.6f, 0.68f})
    if (std::fabs(y - edge * h) < 2.f) return true;
  return false;
}

TEST(Feature, KeepsAlbedoAndNormalEdges) {
  const FeatureScene s = make_feature_scene(160, 120, 0.1f, 0.f, 21, false);
  const FeatureReconstruction r = filter_primal(s);
  const double sigma = 0.1 / std::sqrt(2.0);  // noise of the halves' mean
  const double ours = band_rmse(r.image, s, near_edge);
  const double box = band_rmse(box_of_mean(s, 8), s, near_edge);
  std::printf("edge band RMSE: noise %.4f, feature %.4f, 17x17 box %.4f\n", sigma, ours, box);
  EXPECT_LT(ours, 0.35 * sigma);
  EXPECT_GT(box, 0.6 * sigma);  // the bound is one a plain window filter breaks
}

std::vector<double> true_error(const std::vector<float>& image, const std::vector<float>& truth) {
  std::vector<double> e(image.size() / 3, 0.0);
  for (size_t i = 0; i < image.size(); ++i)
    e[i / 3] += (double(image[i]) - truth[i]) * (double(image[i]) - truth[i]) / 3.0;
  return e;
}

double mean(const std::vector<float>& v) {
  double s = 0.0;
  for (float x : v) s += x;
  return s / double(v.size());
}

// The estimated squared error of the halves' mean against the true one, per candidate: within
// [0.85, 1.15] of it over the image (each half is filtered alone, so the estimate is unbiased)
// and within 2x on at least half of the 32x32 blocks; after the per-pixel choice (which picks the
// luckiest estimates) within [0.6, 1.1].
TEST(Feature, ErrorEstimateMatchesTheTrueError) {
  const FeatureScene s = make_feature_scene(192, 128, 0.15f, 0.05f, 31);
  const detail::FeatureBuffers fb = detail::prepare_feature_buffers(
      s.input(), s.a.data(), s.b.data(), s.primal.data(), nullptr, nullptr);
  const size_t n = size_t(s.w) * s.h;
  std::vector<float> fa(3 * n), fbh(3 * n), error(n), image(3 * n);
  const float* const images[2] = {fb.a.data(), fb.b.data()};
  float* const out[2] = {fa.data(), fbh.data()};
  for (const auto& candidate : detail::default_bilateral_candidates()) {
    detail::bilateral_filter(fb, candidate, images, out, 2);
    detail::candidate_error(fb, fa.data(), fbh.data(), error.data());
    for (size_t i = 0; i < 3 * n; ++i) image[i] = 0.5f * (fa[i] + fbh[i]);
    const std::vector<double> truth = true_error(image, s.truth);
    double tru = 0.0;
    for (double t : truth) tru += t;
    const double ratio = mean(error) / (tru / double(truth.size()));
    int blocks = 0, within = 0;
    for (int by = 0; by + 32 <= s.h; by += 32)
      for (int bx = 0; bx + 32 <= s.w; bx += 32) {
        double e = 0.0, t = 0.0;
        for (int y = by; y < by + 32; ++y)
          for (int x = bx; x < bx + 32; ++x)
            e += error[size_t(y) * s.w + x], t += truth[size_t(y) * s.w + x];
        ++blocks;
        within += e > 0.5 * t && e < 2.0 * t;
      }
    std::printf(
        "radius %d stride %d range %.2f: estimate / true error %.3f, blocks within 2x: %d "
        "of %d\n",
        candidate.window.radius, candidate.window.stride, candidate.range, ratio, within, blocks);
    EXPECT_GT(ratio, 0.85);
    EXPECT_LT(ratio, 1.15);
    EXPECT_GE(2 * within, blocks);
  }
  const FeatureReconstruction r = filter_primal(s);
  double tru = 0.0;
  for (double t : true_error(r.image, s.truth)) tru += t;
  const double ratio = mean(r.error) / (tru / double(r.error.size()));
  std::printf("chosen: estimate / true error %.3f\n", ratio);
  EXPECT_GT(ratio, 0.6);
  EXPECT_LT(ratio, 1.1);
}

// Absent features, and NaN / Inf in the halves and in the features, are missing data: the output
// stays finite and close to the truth, and reconstruct() names what is missing.
TEST(Feature, MissingFeaturesAndNonFiniteInputs) {
  FeatureScene s = make_feature_scene(96, 64, 0.1f, 0.02f, 41);
  const double noise = mse(s.primal, s.truth);
  const FeatureReconstruction bare = filter_primal(s, false);
  std::printf("no features, no gradients: MSE %.3g -> %.3g\n", noise, mse(bare.image, s.truth));
  EXPECT_EQ(bare.features, 0);
  EXPECT_LT(mse(bare.image, s.truth), noise / 2.0);

  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  const FeatureReconstruction clean = filter_primal(s);
  for (int k = 0; k < 40; ++k) {
    const size_t i = size_t(k * 97 + 13) % (size_t(s.w) * s.h);
    if (k % 4 == 0) s.a[3 * i + 1] = nan;
    if (k % 4 == 1) s.b[3 * i] = inf;
    if (k % 4 == 2) s.albedo[3 * i + 2] = nan;
    if (k % 4 == 3) s.depth[i] = -inf;
  }
  const FeatureReconstruction holes = filter_primal(s);
  EXPECT_EQ(holes.missing, 40);
  for (float v : holes.image) ASSERT_TRUE(std::isfinite(v));
  std::printf("with 40 holes: MSE %.3g (clean %.3g)\n", mse(holes.image, s.truth),
              mse(clean.image, s.truth));
  EXPECT_LT(mse(holes.image, s.truth), 1.2 * mse(clean.image, s.truth));

  ReconstructionSettings settings;
  settings.norm = ReconstructionNorm::Feature;
  ReconstructionInput no_b = s.input();
  no_b.primal_b = nullptr;
  EXPECT_THROW(reconstruct(no_b, settings), std::invalid_argument);
  ReconstructionInput no_gradients = s.input();
  no_gradients.gradient_y = nullptr;
  EXPECT_THROW(reconstruct(no_gradients, settings), std::invalid_argument);
  ReconstructionInput three_halves = s.input();
  three_halves.gradient_y_b = nullptr;
  EXPECT_THROW(reconstruct(three_halves, settings), std::invalid_argument);
  settings.feature_guide = ReconstructionNorm::None;
  EXPECT_NO_THROW(reconstruct(no_gradients, settings));
}

// Small bright spots whose features match their dark, flat surroundings (a light seen in a
// mirror, a caustic): away from them the widest filter wins, and the blend of the neighbourhood's
// choices must not bring that filter onto the spots, which it would spread and dim.
TEST(Feature, BlendKeepsBrightSpotsWhereTheyAre) {
  const int w = 120, h = 80;
  FeatureScene s;
  s.w = w, s.h = h;
  const size_t n = size_t(w) * h;
  s.truth.assign(3 * n, 0.1f);
  s.albedo.assign(3 * n, 0.5f);
  s.normal.assign(3 * n, 0.f);
  s.depth.assign(n, 1.f);
  for (size_t i = 0; i < n; ++i) s.normal[3 * i + 2] = 1.f;
  for (int cy : {20, 40, 60})
    for (int cx : {20, 60, 100})
      for (int y = cy - 1; y <= cy + 1; ++y)
        for (int x = cx - 1; x <= cx + 1; ++x)
          for (int c = 0; c < 3; ++c) s.truth[3 * (size_t(y) * w + x) + c] = 20.f;
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 0.05f);
  s.a.resize(3 * n), s.b.resize(3 * n), s.primal.resize(3 * n);
  for (size_t i = 0; i < 3 * n; ++i) {
    s.a[i] = s.truth[i] * (1.f + noise(rng));
    s.b[i] = s.truth[i] * (1.f + noise(rng));
    s.primal[i] = 0.5f * (s.a[i] + s.b[i]);
  }
  const FeatureReconstruction r = filter_primal(s);
  const double before = relative_mse(s.primal, s.truth), after = relative_mse(r.image, s.truth);
  std::printf("bright spots: relMSE %.3g -> %.3g\n", before, after);
  EXPECT_LT(after, before / 4.0);
}

// A flat grey plane (one albedo, normal and depth) with noisy halves: fireflies (1000x the
// truth) in one half only at isolated pixels, and real one-pixel highlights (25x) in both.
struct FireflyScene {
  FeatureScene s;
  std::vector<size_t> fireflies, highlights;
};

FireflyScene make_firefly_scene(float noise_sigma) {
  FireflyScene f;
  FeatureScene& s = f.s;
  const int w = 96, h = 64;
  s.w = w, s.h = h;
  const size_t n = size_t(w) * h;
  s.truth.assign(3 * n, 0.2f);
  s.albedo.assign(3 * n, 0.5f);
  s.normal.assign(3 * n, 0.f);
  s.depth.assign(n, 1.f);
  for (size_t i = 0; i < n; ++i) s.normal[3 * i + 2] = 1.f;
  for (int y = 8; y < h - 8; y += 16)
    for (int x = 8; x < w - 8; x += 16) {
      f.fireflies.push_back(size_t(y) * w + x);
      f.highlights.push_back(size_t(y + 8) * w + x + 8);
    }
  for (size_t i : f.highlights)
    for (int c = 0; c < 3; ++c) s.truth[3 * i + c] = 5.f;
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.f, noise_sigma);
  s.a.resize(3 * n), s.b.resize(3 * n), s.primal.resize(3 * n);
  for (size_t i = 0; i < 3 * n; ++i) {
    s.a[i] = s.truth[i] * (1.f + noise(rng));
    s.b[i] = s.truth[i] * (1.f + noise(rng));
  }
  for (size_t k = 0; k < f.fireflies.size(); ++k)
    for (int c = 0; c < 3; ++c) (k % 2 ? s.b : s.a)[3 * f.fireflies[k] + c] = 200.f;
  for (size_t i = 0; i < 3 * n; ++i) s.primal[i] = 0.5f * (s.a[i] + s.b[i]);
  return f;
}

float luminance(const std::vector<float>& rgb, size_t i) {
  return 0.2126f * rgb[3 * i] + 0.7152f * rgb[3 * i + 1] + 0.0722f * rgb[3 * i + 2];
}

// The limit fires at a one-half firefly only: not at a highlight both halves see, and never once
// the halves agree (converged), so the reconstruction stays consistent.
TEST(Feature, HalfOutliersAreLimitedWhereOneHalfAloneIsBright) {
  FireflyScene f = make_firefly_scene(0.1f);
  FeatureScene& s = f.s;
  std::vector<float> a = s.a, b = s.b, all = s.primal;
  const int fired =
      detail::limit_half_outliers(s.w, s.h, s.a.data(), s.b.data(), a.data(), b.data(), all.data());
  EXPECT_EQ(fired, int(f.fireflies.size()));
  for (size_t i : f.fireflies) {
    EXPECT_LT(luminance(all, i), 4.f * 0.2f) << i;
    EXPECT_LE(std::max(luminance(a, i), luminance(b, i)), 3.f * 1.3f * 0.2f) << i;
  }
  for (size_t i : f.highlights) EXPECT_EQ(luminance(all, i), luminance(s.primal, i)) << i;
  std::vector<float> ta = s.truth, tb = s.truth, tall = s.truth;
  EXPECT_EQ(detail::limit_half_outliers(s.w, s.h, s.truth.data(), s.truth.data(), ta.data(),
                                        tb.data(), tall.data()),
            0);
  EXPECT_EQ(tall, s.truth);
}

// Through the whole Feature filter: no pixel of the flat plane ends up more than 4x the truth
// (an isolated bright speckle), and the real highlights keep most of their light.
TEST(Feature, NoSpecklesFromOneHalfFireflies) {
  const FireflyScene f = make_firefly_scene(0.3f);
  const FeatureScene& s = f.s;
  const FeatureReconstruction r = filter_primal(s);
  int speckles = 0;
  for (size_t i = 0; i < size_t(s.w) * s.h; ++i)
    if (luminance(s.truth, i) < 1.f && luminance(r.image, i) > 4.f * luminance(s.truth, i))
      ++speckles;
  float kept = 1.f;
  for (size_t i : f.highlights) kept = std::min(kept, luminance(r.image, i) / 5.f);
  std::printf("one-half fireflies: %d speckles (limited %d pixels), highlights kept >= %.2f\n",
              speckles, r.limited, kept);
  EXPECT_EQ(speckles, 0);
  EXPECT_GT(kept, 0.5f);
}

// A firefly of one half that the gradient-domain solve of all samples spread onto its 8
// neighbours (as on the demo scene, where it ended 4x the reference): their raised median must not
// keep the pixel bright; the neighbours themselves are left as they are.
TEST(Feature, FireflySpreadByTheSolveIsLimited) {
  const int w = 16, h = 16;
  const size_t n = size_t(w) * h, p = size_t(8) * w + 8;
  std::vector<float> pa(3 * n, 0.2f), pb = pa, all = pa;
  for (int c = 0; c < 3; ++c) pb[3 * p + c] = 3.f, all[3 * p + c] = 1.2f;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (dx || dy)
        for (int c = 0; c < 3; ++c) all[3 * (p + dy * w + dx) + c] = 0.45f;
  std::vector<float> a = pa, b = pb, limited = all;
  EXPECT_EQ(
      detail::limit_half_outliers(w, h, pa.data(), pb.data(), a.data(), b.data(), limited.data()),
      1);
  // Bound 3 x 0.2 on the bright half: all samples scaled to at most 3x the primal's neighbours.
  EXPECT_NEAR(luminance(limited, p), 0.6f, 1e-5f);
  for (size_t i = 0; i < n; ++i)
    if (i != p) {
      EXPECT_EQ(luminance(limited, i), luminance(all, i)) << i;
    }
}

// Both halves bright at one pixel, each carried by one sample (variance of the mean near its mean
// squared): two rare paths, limited to the neighbourhood's bound. The same brightness seen by many
// samples (a small variance), inside a bright region, or without the variances is kept.
TEST(Feature, BothHalfFirefliesCarriedByOneSampleAreLimited) {
  const int w = 16, h = 16;
  const size_t n = size_t(w) * h, p = size_t(5) * w + 5, q = size_t(10) * w + 10;
  std::vector<float> pa(3 * n, 0.2f), pb = pa, va(3 * n, 0.01f), vb = va;
  auto set = [&](size_t i, float value, float variance) {
    for (int c = 0; c < 3; ++c) {
      pa[3 * i + c] = pb[3 * i + c] = value;
      va[3 * i + c] = vb[3 * i + c] = variance;
    }
  };
  set(p, 3.f, 0.9f * 9.f);  // one sample of 48 among 15 dark ones in each half of 16
  set(q, 3.f, 0.9f * 9.f);  // the same at q, but inside a 3x3 bright square
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = 0; dx <= 1; ++dx) set(q + dy * w + dx, 3.f, 0.01f);
  auto limit = [&](const float* variance_a, const float* variance_b, std::vector<float>& out) {
    std::vector<float> a = pa, b = pb;
    out = pa;
    return detail::limit_half_outliers(w, h, pa.data(), pb.data(), a.data(), b.data(), out.data(),
                                       variance_a, variance_b);
  };
  std::vector<float> all;
  EXPECT_EQ(limit(va.data(), vb.data(), all), 1);
  EXPECT_NEAR(luminance(all, p), 3.f * 0.2f, 1e-5f);
  EXPECT_EQ(luminance(all, q), 3.f);
  EXPECT_EQ(limit(nullptr, nullptr, all), 0);
  // Converging: eight samples of each half see it (variance of the mean 7/8 x 9 / 8 of 16).
  set(p, 3.f, 9.f * 7.f / 64.f);
  EXPECT_EQ(limit(va.data(), vb.data(), all), 0);
  EXPECT_EQ(luminance(all, p), 3.f);
}

// Through the whole Feature filter with the halves' variances: a firefly in both halves on the
// flat plane ends below 4x the truth; the real highlights (variances of many samples) keep their
// light.
TEST(Feature, NoSpecklesFromBothHalfFireflies) {
  FireflyScene f = make_firefly_scene(0.1f);
  FeatureScene& s = f.s;
  const size_t n = size_t(s.w) * s.h;
  std::vector<float> va(3 * n), vb(3 * n);
  for (size_t i = 0; i < 3 * n; ++i) {
    va[i] = vb[i] = 0.01f * s.truth[i] * s.truth[i];
    s.a[i] = s.b[i] = s.primal[i] = 0.5f * (s.a[i] + s.b[i]);  // both halves have each firefly
  }
  for (size_t i : f.fireflies)
    for (int c = 0; c < 3; ++c) va[3 * i + c] = vb[3 * i + c] = 0.9f * 100.f * 100.f;
  ReconstructionInput in = s.input();
  in.variance_a = va.data(), in.variance_b = vb.data();
  const FeatureReconstruction r = feature_filter(in, s.a.data(), s.b.data(), s.primal.data());
  float worst = 0.f, kept = 1.f;
  for (size_t i : f.fireflies) worst = std::max(worst, luminance(r.image, i) / 0.2f);
  for (size_t i : f.highlights) kept = std::min(kept, luminance(r.image, i) / 5.f);
  std::printf(
      "both-half fireflies: worst %.2fx the truth (limited %d pixels), highlights kept "
      ">= %.2f\n",
      worst, r.limited, kept);
  EXPECT_EQ(r.limited, int(f.fireflies.size()));
  EXPECT_LT(worst, 4.f);
  EXPECT_GT(kept, 0.5f);
  const FeatureReconstruction plain = filter_primal(s);  // no variances: the fireflies stay
  float plain_worst = 0.f;
  for (size_t i : f.fireflies)
    plain_worst = std::max(plain_worst, luminance(plain.image, i) / 0.2f);
  EXPECT_GT(plain_worst, 4.f);
}

TEST(Feature, SameResultOnOneAndTwoThreads) {
  const FeatureScene s = make_feature_scene(150, 70, 0.15f, 0.02f, 51);
  ReconstructionSettings settings;
  settings.norm = ReconstructionNorm::Feature;
  settings.threads = 1;
  const std::vector<float> one = reconstruct(s.input(), settings);
  settings.threads = 2;
  const std::vector<float> two = reconstruct(s.input(), settings);
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(float)), 0);
}

// Equal input (the same halves, their mean, the same gradients and gradient halves): relMSE of
// Feature against L1 on the room, which has albedo, normal and shadow edges and smooth lighting;
// without the gradient halves the primal is filtered (and reported so).
TEST(Feature, BeatsL1AtEqualInput) {
  // Half noise 0.2 (0.14 for their mean), gradient noise 0.1.
  const FeatureScene s = make_feature_scene(256, 192, 0.2f, 0.1f, 61);
  ReconstructionSettings settings;
  settings.norm = ReconstructionNorm::L1;
  const double l1 = relative_mse(reconstruct(s.input(), settings), s.truth);
  settings.norm = ReconstructionNorm::Feature;
  ReconstructionReport report;
  const double feature = relative_mse(reconstruct(s.input(), settings, &report), s.truth);
  EXPECT_FALSE(report.feature_filtered_primal);
  ReconstructionInput no_halves = s.input();
  no_halves.gradient_x_a = no_halves.gradient_x_b = nullptr;
  no_halves.gradient_y_a = no_halves.gradient_y_b = nullptr;
  const double primal = relative_mse(reconstruct(no_halves, settings, &report), s.truth);
  EXPECT_TRUE(report.feature_filtered_primal);
  std::printf(
      "relMSE: primal %.3g, L1 %.3g, feature %.3g (L1 / feature = %.2f), feature on the primal "
      "%.3g\n",
      relative_mse(s.primal, s.truth), l1, feature, l1 / feature, primal);
  EXPECT_LT(feature, l1 / 4.0);
}

// Where the features explain nothing (no feature buffers) the choice must fall back to the
// gradient-domain solution instead of blurring it: never much worse than L1.
TEST(Feature, NoWorseThanL1WithoutFeatures) {
  const FeatureScene s = make_feature_scene(256, 192, 0.2f, 0.05f, 71);
  ReconstructionSettings settings;
  settings.norm = ReconstructionNorm::L1;
  const double l1 = relative_mse(reconstruct(s.input(false), settings), s.truth);
  settings.norm = ReconstructionNorm::Feature;
  const double feature = relative_mse(reconstruct(s.input(false), settings), s.truth);
  std::printf("no features: relMSE L1 %.3g, feature %.3g (%.2fx)\n", l1, feature, l1 / feature);
  EXPECT_LT(feature, 1.05 * l1);
}

}  // namespace
}  // namespace gdpt
