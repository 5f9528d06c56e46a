#include "reconstruct/feature_bilateral.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

namespace {

inline constexpr int kMaxImages = 3;
inline constexpr int kMaxRanges = kColourToleranceCount;
// Feature distances beyond this give weights below 1e-5 of the centre's: skipped.
inline constexpr float kNegligibleDistance = 23.f;
// Keeps the relative colour tolerance finite on black pixels.
inline constexpr float kRangeFloor = 1e-3f;

// -log of the feature weight between pixels i and j (before the factor 1/2).
float feature_distance(const FeatureBuffers& fb, size_t i, size_t j) {
  const float* fi = fb.feature.data() + kFeatureChannels * i;
  const float* fj = fb.feature.data() + kFeatureChannels * j;
  const float* vi = fb.feature_var.data() + kFeatureChannels * i;
  const float* vj = fb.feature_var.data() + kFeatureChannels * j;
  const float ta = kAlbedoTolerance * kAlbedoTolerance, tn = kNormalTolerance * kNormalTolerance;
  const float td = kDepthTolerance * fi[6];
  float d = 0.f;
  for (int c = 0; c < 3; ++c) {
    const float da = fi[c] - fj[c], dn = fi[3 + c] - fj[3 + c];
    d += da * da / (ta + vi[c] + vj[c]) + dn * dn / (tn + vi[3 + c] + vj[3 + c]);
  }
  const float dd = fi[6] - fj[6];
  if (dd != 0.f) d += dd * dd / (td * td + vi[6] + vj[6] + 1e-12f);
  return d;
}

// The identity, except that a missing pixel takes the mean of its valid 3x3 neighbours (its
// value is 0 in the masked images, which no error estimate can see: it has no halves).
void identity_filter(const FeatureBuffers& fb, const float* const* images, float* const* out,
                     int count) {
  const int W = fb.width, H = fb.height;
  for (int k = 0; k < count; ++k) std::memcpy(out[k], images[k], sizeof(float) * 3 * size_t(W) * H);
  parallel_rows(H, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        if (fb.valid[i] & kImagesValid) continue;
        for (int k = 0; k < count; ++k) {
          float sum[3] = {0.f, 0.f, 0.f}, n = 0.f;
          for (int yy = std::max(0, y - 1); yy <= std::min(H - 1, y + 1); ++yy)
            for (int xx = std::max(0, x - 1); xx <= std::min(W - 1, x + 1); ++xx) {
              const size_t j = size_t(yy) * W + xx;
              if (!(fb.valid[j] & kImagesValid)) continue;
              for (int c = 0; c < 3; ++c) sum[c] += images[k][3 * j + c];
              n += 1.f;
            }
          for (int c = 0; c < 3; ++c) out[k][3 * i + c] = n > 0.f ? sum[c] / n : 0.f;
        }
      }
  });
}

}  // namespace

std::vector<BilateralCandidate> default_bilateral_candidates() {
  std::vector<BilateralCandidate> c = {{{0, 1}, 0.f}};
  for (const BilateralWindow& w : kWindows)
    for (float range : kColourTolerances) c.push_back({w, range});
  return c;
}

void bilateral_filter(const FeatureBuffers& fb, const BilateralWindow& window, const float* ranges,
                      int range_count, const float* const* images, int count, float* const* out) {
  const int W = fb.width, H = fb.height, r = window.radius, step = window.stride;
  if (r == 0) {
    for (int t = 0; t < range_count; ++t) identity_filter(fb, images, out + t * count, count);
    return;
  }
  float inv_range2[kMaxRanges];
  for (int t = 0; t < range_count; ++t)
    inv_range2[t] = ranges[t] > 0.f ? 1.f / (ranges[t] * ranges[t]) : 0.f;
  parallel_rows(H, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        const bool centre_features = fb.valid[i] & kFeaturesValid;
        // A missing centre has no colour to compare with: features alone weigh its neighbours.
        const bool centre_colour = fb.valid[i] & kImagesValid;
        float num[kMaxRanges][kMaxImages][3] = {}, den[kMaxRanges][kMaxImages] = {};
        float scale[kMaxImages];
        for (int k = 0; k < count; ++k) {
          const float* p = images[k] + 3 * i;
          const float lum = std::max(0.f, (p[0] + p[1] + p[2]) * (1.f / 3.f)) + kRangeFloor;
          scale[k] = centre_colour ? 1.f / (3.f * lum * lum) : 0.f;
        }
        for (int dy = -r; dy <= r; dy += step) {
          const int yy = y + dy;
          if (yy < 0 || yy >= H) continue;
          for (int dx = -r; dx <= r; dx += step) {
            const int xx = x + dx;
            if (xx < 0 || xx >= W) continue;
            const size_t j = size_t(yy) * W + xx;
            if (!(fb.valid[j] & kImagesValid)) continue;
            if (!centre_features && j != i) continue;
            float df = 0.f;
            if (centre_features) {
              if (!(fb.valid[j] & kFeaturesValid)) continue;
              df = feature_distance(fb, i, j);
              if (df > kNegligibleDistance) continue;
            }
            const float wf = std::exp(-0.5f * df);
            for (int k = 0; k < count; ++k) {
              const float *p = images[k] + 3 * i, *q = images[k] + 3 * j;
              const float d0 = q[0] - p[0], d1 = q[1] - p[1], d2 = q[2] - p[2];
              const float dc = (d0 * d0 + d1 * d1 + d2 * d2) * scale[k];
              for (int t = 0; t < range_count; ++t) {
                const float w =
                    inv_range2[t] > 0.f ? wf * std::exp(-0.5f * dc * inv_range2[t]) : wf;
                for (int c = 0; c < 3; ++c) num[t][k][c] += w * q[c];
                den[t][k] += w;
              }
            }
          }
        }
        for (int t = 0; t < range_count; ++t)
          for (int k = 0; k < count; ++k)
            for (int c = 0; c < 3; ++c)
              out[t * count + k][3 * i + c] =
                  den[t][k] > 0.f ? num[t][k][c] / den[t][k] : images[k][3 * i + c];
      }
  });
}

}  // namespace gdpt::detail
