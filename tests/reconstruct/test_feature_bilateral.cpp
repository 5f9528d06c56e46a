// The feature filters (feature_bilateral.h) against a direct per-pixel implementation of the
// same weights: every window and colour tolerance, with feature variances, missing pixels and
// missing features, all within float rounding.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>
#include <random>
#include <vector>

#include "reconstruct/candidate_selection.h"
#include "reconstruct/feature_bilateral.h"
#include "reconstruct/feature_buffers.h"
#include "testing/feature_scene.h"

namespace gdpt {
namespace {

// One candidate, tap by tap: weight = feature weight (over the tolerances plus both pixels'
// variances, taps beyond distance 23 left out) times the colour weight relative to the centre's
// brightness; a centre without features keeps its own colour.
std::vector<float> reference_filter(const detail::FeatureBuffers& fb,
                                    const detail::BilateralCandidate& cand, const float* image) {
  const int W = fb.width, H = fb.height, r = cand.window.radius, step = cand.window.stride;
  const size_t n = size_t(W) * H;
  auto f = [&](int c, size_t i) { return double(fb.feature[c * n + i]); };
  auto v = [&](int c, size_t i) { return double(fb.feature_var[c * n + i]); };
  const double tol[7] = {0.05, 0.05, 0.05, 0.1, 0.1, 0.1, 0.0};
  std::vector<float> out(3 * n);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * W + x;
      const bool centre_features = fb.valid[i] & detail::kFeaturesValid;
      const bool centre_colour = fb.valid[i] & detail::kImagesValid;
      const float* p = image + 3 * i;
      const double lum = std::max(0.0, (double(p[0]) + p[1] + p[2]) / 3.0) + 1e-3;
      double num[3] = {0, 0, 0}, den = 0;
      for (int dy = -r; dy <= r; dy += step)
        for (int dx = -r; dx <= r; dx += step) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || xx >= W || yy < 0 || yy >= H) continue;
          const size_t j = size_t(yy) * W + xx;
          if (!(fb.valid[j] & detail::kImagesValid)) continue;
          double d = 0.0;
          if (centre_features) {
            if (!(fb.valid[j] & detail::kFeaturesValid)) continue;
            for (int c = 0; c < 7; ++c) {
              const double t = c < 6 ? tol[c] : 0.05 * f(6, i);
              const double e = f(c, i) - f(c, j);
              if (e != 0.0) d += e * e / (t * t + v(c, i) + v(c, j) + (c == 6 ? 1e-12 : 0.0));
            }
            if (d > 23.0) continue;
          } else if (j != i) {
            continue;
          }
          double w = std::exp(-0.5 * d);
          if (cand.range > 0.f && centre_colour) {
            double dc = 0.0;
            for (int c = 0; c < 3; ++c)
              dc += (double(image[3 * j + c]) - p[c]) * (image[3 * j + c] - p[c]);
            w *= std::exp(-0.5 * dc / (3.0 * lum * lum) / (double(cand.range) * cand.range));
          }
          for (int c = 0; c < 3; ++c) num[c] += w * image[3 * j + c];
          den += w;
        }
      for (int c = 0; c < 3; ++c) out[3 * i + c] = den > 0.0 ? float(num[c] / den) : p[c];
    }
  return out;
}

// The synthetic room with random feature variances and 30 missing pixels (a half, a normal or
// a depth not finite), its scene kept alive in `s`.
detail::FeatureBuffers noisy_buffers(test::FeatureScene& s) {
  s = test::make_feature_scene(90, 61, 0.2f, 0.f, 17);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<float> albedo_var(s.albedo.size()), normal_var(s.normal.size()),
      depth_var(s.depth.size());
  for (float& x : albedo_var) x = 5e-2f * u(rng);
  for (float& x : normal_var) x = 2e-2f * u(rng);
  for (float& x : depth_var) x = 5e-2f * u(rng);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int k = 0; k < 30; ++k) {
    const size_t i = size_t(k * 181 + 7) % (size_t(s.w) * s.h);
    if (k % 3 == 0) s.a[3 * i] = nan;
    if (k % 3 == 1) s.normal[3 * i + 1] = nan;
    if (k % 3 == 2) s.depth[i] = std::numeric_limits<float>::infinity();
  }
  ReconstructionInput in = s.input();
  in.albedo_variance = albedo_var.data();
  in.normal_variance = normal_var.data();
  in.depth_variance = depth_var.data();
  return detail::prepare_feature_buffers(in, s.a.data(), s.b.data(), s.primal.data(), nullptr,
                                         nullptr);
}

TEST(FeatureBilateral, EveryCandidateMatchesTheDirectFilter) {
  test::FeatureScene s;
  const detail::FeatureBuffers fb = noisy_buffers(s);
  ASSERT_EQ(fb.missing, 30);
  const size_t n3 = 3 * size_t(s.w) * s.h;
  const float* const images[2] = {fb.a.data(), fb.b.data()};
  // Per window, all colour tolerances in one call (as the reconstruction filters them) and each
  // alone.
  constexpr int kTol = detail::kColourToleranceCount;
  std::vector<float> all(2 * kTol * n3), alone(2 * n3);
  float* out[2 * kTol];
  for (int k = 0; k < 2 * kTol; ++k) out[k] = all.data() + k * n3;
  float* const out_alone[2] = {alone.data(), alone.data() + n3};
  for (const detail::BilateralWindow& window : detail::kWindows) {
    detail::bilateral_filter(fb, window, detail::kColourTolerances, kTol, images, 2, out);
    for (int t = 0; t < kTol; ++t) {
      const detail::BilateralCandidate cand{window, detail::kColourTolerances[t]};
      detail::bilateral_filter(fb, cand, images, out_alone, 2);
      double worst = 0.0, worst_alone = 0.0, changed = 0.0;
      for (int k = 0; k < 2; ++k) {
        const std::vector<float> ref = reference_filter(fb, cand, images[k]);
        const float *got = out[2 * t + k], *got_alone = out_alone[k];
        for (size_t i = 0; i < n3; ++i) {
          // Relative to the value, or to 0.01 where a mean of noisy values cancels to near 0.
          const double scale = std::max(std::abs(double(ref[i])), 1e-2);
          worst = std::max(worst, std::abs(double(got[i]) - ref[i]) / scale);
          worst_alone = std::max(worst_alone, std::abs(double(got_alone[i]) - ref[i]) / scale);
          changed = std::max(changed, std::abs(double(ref[i]) - images[k][i]));
        }
      }
      std::printf(
          "radius %d stride %d range %.2f: worst relative difference %.2g (tolerances in one "
          "call), %.2g (alone)\n",
          window.radius, window.stride, cand.range, worst, worst_alone);
      EXPECT_LT(worst, 1e-5);
      EXPECT_LT(worst_alone, 1e-5);
      EXPECT_GT(changed, 0.05);  // the filter does filter
    }
  }
}

// All windows in one pass (taps shared by several windows weighed once), writing the halves'
// error estimates: bit for bit what each window filtered alone and candidate_error give, with and
// without the relative weights and the output factor.
TEST(FeatureBilateral, CandidatesInOnePassMatchEachWindowBitForBit) {
  test::FeatureScene s;
  const detail::FeatureBuffers fb = noisy_buffers(s);
  const size_t n = size_t(s.w) * s.h, n3 = 3 * n;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.5f, 2.f);
  std::vector<float> weight(n3), multiply(n3);
  for (float& x : weight) x = u(rng);
  for (float& x : multiply) x = u(rng);
  const float* const images[3] = {fb.a.data(), fb.b.data(), fb.all.data()};
  constexpr int kTol = detail::kColourToleranceCount;
  constexpr int kWin = int(std::size(detail::kWindows));
  for (const bool extras : {false, true}) {
    const float* w = extras ? weight.data() : nullptr;
    const float* m = extras ? multiply.data() : nullptr;
    std::vector<float> fused(kWin * kTol * n3), error(kWin * kTol * n), relative(kWin * kTol * n);
    float* out[kWin * kTol];
    detail::CandidateEstimates est[kWin * kTol];
    for (int c = 0; c < kWin * kTol; ++c) {
      out[c] = fused.data() + c * n3;
      est[c] = {error.data() + c * n, extras ? relative.data() + c * n : nullptr};
    }
    detail::bilateral_candidates(fb, detail::kWindows, kWin, detail::kColourTolerances, kTol,
                                 images, out, est, w, m);
    int differing = 0;
    for (int win = 0; win < kWin; ++win) {
      std::vector<float> one(3 * kTol * n3), e(n), r(n);
      float* one_out[3 * kTol];
      for (int k = 0; k < 3 * kTol; ++k) one_out[k] = one.data() + k * n3;
      detail::bilateral_filter(fb, detail::kWindows[win], detail::kColourTolerances, kTol, images,
                               3, one_out, m);
      for (int t = 0; t < kTol; ++t) {
        const int c = win * kTol + t;
        detail::candidate_error(fb, one_out[3 * t], one_out[3 * t + 1], e.data(), w, r.data());
        differing += std::memcmp(one_out[3 * t + 2], out[c], sizeof(float) * n3) != 0;
        differing += std::memcmp(e.data(), est[c].error, sizeof(float) * n) != 0;
        if (extras) differing += std::memcmp(r.data(), est[c].relative, sizeof(float) * n) != 0;
        // The estimate is not trivially 0 (a real error, of either sign).
        EXPECT_GT(*std::max_element(e.begin(), e.end()), 1e-4f);
      }
    }
    EXPECT_EQ(differing, 0) << (extras ? "with" : "without") << " weights and factor";
  }
}

// Sparse light on a flat plane (x < 32): each half is 16 samples, each lit (6.4) with
// probability 1/32, so the truth is 0.2 and most pixels are 0 or 0.4 or more, given with the
// variance of their mean; beside it (x >= 32) a lit floor at 2.0 with 1% noise, a lighting edge no
// feature shows. With the noise in the colour distance the relative tolerances average the
// sparse light (without it a lit pixel's neighbours are too far from it and the noise stays), and
// the lighting edge, far beyond the noise, stays sharp.
TEST(FeatureBilateral, DifferencesTheNoiseExplainsAreAveraged) {
  test::FeatureScene s;
  s.w = 64, s.h = 48;
  const size_t n = size_t(s.w) * s.h;
  s.albedo.assign(3 * n, 0.5f), s.normal.assign(3 * n, 0.f), s.depth.assign(n, 1.f);
  for (size_t i = 0; i < n; ++i) s.normal[3 * i + 2] = 1.f;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> gauss(0.f, 0.02f);
  s.a.resize(3 * n), s.b.resize(3 * n), s.primal.resize(3 * n), s.truth.resize(3 * n);
  std::vector<float> va(3 * n), vb(3 * n);
  for (size_t i = 0; i < n; ++i)
    for (int half = 0; half < 2; ++half) {
      float sum = 0.f, sum2 = 0.f;
      const bool sparse = int(i % s.w) < 32;
      for (int k = 0; k < 16; ++k) {
        const float x =
            sparse ? (u(rng) < 1.f / 32.f ? 6.4f : 0.f) : 2.f * (1.f + 4.f * gauss(rng));
        sum += x, sum2 += x * x;
      }
      const float mean = sum / 16.f, var = std::max(0.f, sum2 - 16.f * mean * mean) / 15.f / 16.f;
      for (int c = 0; c < 3; ++c) {
        (half ? s.b : s.a)[3 * i + c] = mean;
        (half ? vb : va)[3 * i + c] = var;
        s.truth[3 * i + c] = sparse ? 0.2f : 2.f;
      }
    }
  for (size_t k = 0; k < 3 * n; ++k) s.primal[k] = 0.5f * (s.a[k] + s.b[k]);
  const detail::FeatureBuffers fb = detail::prepare_feature_buffers(
      s.input(), s.a.data(), s.b.data(), s.primal.data(), va.data(), vb.data());
  std::vector<float> noise(3 * n);  // per image: the variance summed over RGB
  for (size_t i = 0; i < n; ++i) {
    noise[i] = 3.f * va[3 * i], noise[n + i] = 3.f * vb[3 * i];
    noise[2 * n + i] = 0.25f * (noise[i] + noise[n + i]);
  }
  const float* const planes[3] = {noise.data(), noise.data() + n, noise.data() + 2 * n};
  const float* const images[3] = {fb.a.data(), fb.b.data(), fb.all.data()};
  constexpr int kTol = detail::kColourToleranceCount, kWin = int(std::size(detail::kWindows));
  // Per candidate: MSE over the sparse light (2 px off the edges), and the worst relative error
  // of the lit floor's first column.
  auto measure = [&](const float* const* noise_planes, int candidate) {
    std::vector<float> all(kWin * kTol * 3 * n), error(kWin * kTol * n);
    float* out[kWin * kTol];
    detail::CandidateEstimates est[kWin * kTol];
    for (int c = 0; c < kWin * kTol; ++c)
      out[c] = all.data() + 3 * n * c, est[c] = {error.data() + n * c, nullptr};
    detail::bilateral_candidates(fb, detail::kWindows, kWin, detail::kColourTolerances, kTol,
                                 images, out, est, nullptr, nullptr, noise_planes);
    const float* o = out[candidate];
    double mse = 0.0, count = 0.0, edge = 0.0;
    for (int y = 2; y < s.h - 2; ++y) {
      for (int x = 2; x < 30; ++x, count += 1.0)
        for (int c = 0; c < 3; ++c) mse += std::pow(o[3 * (size_t(y) * s.w + x) + c] - 0.2, 2);
      edge = std::max(edge, std::fabs(o[3 * (size_t(y) * s.w + 32)] - 2.0) / 2.0);
    }
    return std::pair<double, double>(mse / (3.0 * count), edge);
  };
  for (int t = 0; t < 2; ++t) {  // the tolerances 0.05 and 0.2, 7 px window
    const int candidate = 2 * kTol + t;
    const auto [plain_mse, plain_edge] = measure(nullptr, candidate);
    const auto [noisy_mse, noisy_edge] = measure(planes, candidate);
    std::printf("tolerance %.2f: sparse light MSE %.4f -> %.4f, lit edge error %.4f -> %.4f\n",
                detail::kColourTolerances[t], plain_mse, noisy_mse, plain_edge, noisy_edge);
    EXPECT_LT(noisy_mse, plain_mse / 4.0);
    EXPECT_LT(noisy_edge, 0.02);
  }
}

// The AVX2 and AVX-512 builds of the filters' loops against the baseline build, bit for bit: every
// candidate and error estimate, with relative weights, output factor, per-pixel noise and the
// tolerant (noise-free) colour weights of bilateral_filter.
TEST(FeatureBilateral, WiderBuildsMatchTheBaselineBitForBit) {
  using detail::FilterBuild;
  if (!detail::filter_build_available(FilterBuild::Avx2) &&
      !detail::filter_build_available(FilterBuild::Avx512))
    GTEST_SKIP() << "no AVX2 or AVX-512 build on this CPU or tree";
  test::FeatureScene s;
  const detail::FeatureBuffers fb = noisy_buffers(s);
  const size_t n = size_t(s.w) * s.h, n3 = 3 * n;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.5f, 2.f), v(0.f, 0.05f);
  std::vector<float> weight(n3), multiply(n3), noise(3 * n);
  for (float& x : weight) x = u(rng);
  for (float& x : multiply) x = u(rng);
  for (float& x : noise) x = v(rng);
  const float* const planes[3] = {noise.data(), noise.data() + n, noise.data() + 2 * n};
  const float* const images[3] = {fb.a.data(), fb.b.data(), fb.all.data()};
  constexpr int kTol = detail::kColourToleranceCount, kWin = int(std::size(detail::kWindows));
  auto run = [&](FilterBuild build) {
    detail::limit_filter_build(build);
    std::vector<float> all((kWin * kTol + 3 * kTol) * n3 + 2 * kWin * kTol * n);
    float* out[kWin * kTol];
    detail::CandidateEstimates est[kWin * kTol];
    float* p = all.data();
    for (int c = 0; c < kWin * kTol; ++c, p += n3) out[c] = p;
    for (int c = 0; c < kWin * kTol; ++c, p += 2 * n) est[c] = {p, p + n};
    detail::bilateral_candidates(fb, detail::kWindows, kWin, detail::kColourTolerances, kTol,
                                 images, out, est, weight.data(), multiply.data(), planes);
    float* tolerant[3 * kTol];
    for (int k = 0; k < 3 * kTol; ++k, p += n3) tolerant[k] = p;
    detail::bilateral_filter(fb, detail::kWindows[3], detail::kColourTolerances, kTol, images, 3,
                             tolerant, multiply.data());
    detail::limit_filter_build(FilterBuild::Avx512);
    return all;
  };
  const std::vector<float> baseline = run(FilterBuild::Baseline);
  for (const FilterBuild build : {FilterBuild::Avx2, FilterBuild::Avx512}) {
    if (!detail::filter_build_available(build)) continue;
    const std::vector<float> wide = run(build);
    size_t differing = 0;
    for (size_t i = 0; i < wide.size(); ++i)
      differing += std::memcmp(&wide[i], &baseline[i], sizeof(float)) != 0;
    EXPECT_EQ(differing, 0u) << "build " << int(build) << ", of " << wide.size();
  }
  // The error estimates are written (not the zeros the buffer started with).
  const float* first_error = baseline.data() + size_t(kWin * kTol) * n3;
  EXPECT_GT(*std::max_element(first_error, first_error + n), 1e-4f);
}

}  // namespace
}  // namespace gdpt
