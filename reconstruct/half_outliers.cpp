#include "reconstruct/half_outliers.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/huge_pages.h"
#include "reconstruct/parallel.h"

namespace gdpt::detail {

namespace {

float luminance(const float* rgb) {
  return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2];
}

// Median of the finite values of `m` over the 8 neighbours of (x, y), clipped to the image.
float neighbour_median(const float* m, int width, int height, int x, int y) {
  float v[8];
  int count = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int nx = x + dx, ny = y + dy;
      if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
      const float value = m[size_t(ny) * width + nx];
      if (std::isfinite(value)) v[count++] = value;
    }
  if (count == 0) return 0.f;
  std::nth_element(v, v + count / 2, v + count);
  return v[count / 2];
}

// The factor that lowers `value` by `scale`, but not below `floor`; 1 when value is not above it.
float limited_scale(float scale, float value, float floor) {
  if (!(value > floor)) return 1.f;
  return std::max(scale, floor / value);
}

// Written in full by one parallel pass (fresh pages, no zero fill).
struct Luminances {
  FreshHugeVector<float> pa, pb, primal_mean, a, b, half_mean, all;
};

Luminances luminances(int width, int height, const float* primal_a, const float* primal_b,
                      const float* a, const float* b, const float* all) {
  const size_t n = size_t(width) * height;
  Luminances l;
  for (FreshHugeVector<float>* v : {&l.pa, &l.pb, &l.primal_mean, &l.a, &l.b, &l.half_mean, &l.all})
    v->resize(n);
  parallel_rows(height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * width; i < size_t(y1) * width; ++i) {
      l.pa[i] = luminance(primal_a + 3 * i), l.pb[i] = luminance(primal_b + 3 * i);
      l.primal_mean[i] = 0.5f * (l.pa[i] + l.pb[i]);
      l.a[i] = luminance(a + 3 * i), l.b[i] = luminance(b + 3 * i);
      l.half_mean[i] = 0.5f * (l.a[i] + l.b[i]);
      l.all[i] = luminance(all + 3 * i);
    }
  });
  return l;
}

// Luminance of an RGB variance whose channels move together, as where one sample carries the
// pixel: the square of the luminance of the standard deviations.
float luminance_variance(const float* v) {
  const float sd[3] = {std::sqrt(std::max(v[0], 0.f)), std::sqrt(std::max(v[1], 0.f)),
                       std::sqrt(std::max(v[2], 0.f))};
  const float l = luminance(sd);
  return l * l;
}

// Whether one sample carries a half's pixel: the variance of its mean at least
// kHalfDominance times its mean squared.
bool one_sample_carries(const float* variance, size_t i, float mean) {
  return luminance_variance(variance + 3 * i) >= kHalfDominance * mean * mean;
}

}  // namespace

int limit_half_outliers(int width, int height, const float* primal_a, const float* primal_b,
                        float* a, float* b, float* all, const float* variance_a,
                        const float* variance_b) {
  const size_t n = size_t(width) * height;
  const Luminances l = luminances(width, height, primal_a, primal_b, a, b, all);
  const bool dominance = variance_a && variance_b;
  FreshHugeVector<float> scale_a(n), scale_b(n), scale_all(n);  // set per pixel below
  std::vector<int> fired(height, 0);
  parallel_rows(height, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x) {
        const size_t i = size_t(y) * width + x;
        scale_a[i] = scale_b[i] = scale_all[i] = 1.f;
        if (!std::isfinite(l.primal_mean[i]) || !std::isfinite(l.half_mean[i]) ||
            !std::isfinite(l.all[i]))
          continue;
        const bool a_high = l.pa[i] > l.pb[i];
        const float high = a_high ? l.pa[i] : l.pb[i], low = a_high ? l.pb[i] : l.pa[i];
        const float around = neighbour_median(l.primal_mean.data(), width, height, x, y);
        const float bound = kHalfOutlierRatio * std::max({low, around, kHalfOutlierFloor});
        const float both_bound = kHalfOutlierRatio * std::max(around, kHalfOutlierFloor);
        const bool one_half = high > bound;
        const bool both_halves = !one_half && dominance && low > both_bound &&
                                 one_sample_carries(variance_a, i, l.pa[i]) &&
                                 one_sample_carries(variance_b, i, l.pb[i]);
        if (!one_half && !both_halves) continue;
        const float half_floor =
            kHalfOutlierRatio *
            std::max(neighbour_median(l.half_mean.data(), width, height, x, y), kHalfOutlierFloor);
        // The solve spreads the firefly onto its neighbours: their level is the lower of the
        // solve's and the primal's.
        const float all_floor =
            kHalfOutlierRatio *
            std::max(std::min(neighbour_median(l.all.data(), width, height, x, y), around),
                     kHalfOutlierFloor);
        if (one_half) {
          const float rest = std::max(low, 0.f);  // high > bound > 0: the ratios are finite
          (a_high ? scale_a : scale_b)[i] =
              limited_scale(bound / high, a_high ? l.a[i] : l.b[i], half_floor);
          scale_all[i] = limited_scale((bound + rest) / (high + rest), l.all[i], all_floor);
        } else {  // both halves to the neighbourhood's bound (low > both_bound > 0)
          scale_a[i] = limited_scale(both_bound / l.pa[i], l.a[i], half_floor);
          scale_b[i] = limited_scale(both_bound / l.pb[i], l.b[i], half_floor);
          scale_all[i] = limited_scale(both_bound / l.primal_mean[i], l.all[i], all_floor);
        }
        ++fired[y];
      }
  });
  parallel_rows(height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * width; i < size_t(y1) * width; ++i)
      for (int c = 0; c < 3; ++c) {
        a[3 * i + c] *= scale_a[i];
        b[3 * i + c] *= scale_b[i];
        all[3 * i + c] *= scale_all[i];
      }
  });
  int total = 0;
  for (int count : fired) total += count;
  return total;
}

}  // namespace gdpt::detail
