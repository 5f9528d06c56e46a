#include "integrators/adaptive_sampling.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

namespace gdpt {

namespace {
// Cycles' floor under sqrt(I): a black pixel with no noise has converged, not 0 / 0.
constexpr double kLuminanceFloor = 1e-4;
// 64 samples estimate a near-Gaussian pixel noise to about 10%.
constexpr int kMaxAutomaticMinSamples = 64;
}  // namespace

int adaptive_min_samples(const RenderSettings& settings) {
  // At most kMaxAutomaticMinSamples: a time-limited render asks for an unbounded count.
  const int automatic = std::clamp((settings.samples / 4 + 1) / 2 * 2, 4, kMaxAutomaticMinSamples);
  int m = settings.adaptive_min_samples > 0 ? settings.adaptive_min_samples : automatic;
  if (settings.feature_passes) m += m % 2;  // pixels stop at even counts only: start at one
  return std::min(m, settings.samples);
}

double adaptive_noise(const Film& film, size_t i) {
  return std::sqrt(film.pixel_variance(i)) /
         (kLuminanceFloor + std::sqrt(std::max(0.0, film.pixel_luminance(i))));
}

size_t update_sampling_mask(const Film& film, float threshold, std::vector<uint8_t>& mask) {
  const int W = film.width(), H = film.height();
  const size_t n = film.pixel_count();
  std::vector<uint8_t> noisy(n);
  if (mask.size() != n) mask.assign(n, 1);
  tbb::parallel_for(tbb::blocked_range<int>(0, H, 8), [&](const tbb::blocked_range<int>& r) {
    for (size_t i = size_t(r.begin()) * W; i < size_t(r.end()) * W; ++i)
      noisy[i] = !(adaptive_noise(film, i) < threshold);  // NaN keeps sampling
  });
  // A pixel keeps sampling while it or a 3x3 neighbour is noisy; a pixel that stopped stays
  // stopped (its samples stay the prefix of its sample indices).
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, H, 8), size_t(0),
      [&](const tbb::blocked_range<int>& r, size_t active) {
        for (int y = r.begin(); y < r.end(); ++y)
          for (int x = 0; x < W; ++x) {
            uint8_t& keep = mask[size_t(y) * W + x];
            if (!keep) continue;
            uint8_t any = 0;
            for (int yy = std::max(0, y - 1); yy <= std::min(H - 1, y + 1); ++yy)
              for (int xx = std::max(0, x - 1); xx <= std::min(W - 1, x + 1); ++xx)
                any |= noisy[size_t(yy) * W + xx];
            keep = any;
            active += any;
          }
        return active;
      },
      [](size_t a, size_t b) { return a + b; });
}

}  // namespace gdpt
