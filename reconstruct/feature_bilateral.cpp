#include "reconstruct/feature_bilateral.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

namespace {

inline constexpr int kMaxImages = 3;
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
  std::vector<BilateralCandidate> c = {{0, 0.f}};
  for (int radius : {1, 2, 3, 5})
    for (float range : {0.05f, 0.2f, 0.f}) c.push_back({radius, range});
  return c;
}

void bilateral_filter(const FeatureBuffers& fb, const BilateralCandidate& candidate,
                      const float* const* images, float* const* out, int count) {
  const int W = fb.width, H = fb.height, r = candidate.radius;
  if (r == 0) {
    identity_filter(fb, images, out, count);
    return;
  }
  const float inv_range2 = candidate.range > 0.f ? 1.f / (candidate.range * candidate.range) : 0.f;
  parallel_rows(H, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        const bool centre_features = fb.valid[i] & kFeaturesValid;
        // A missing centre has no colour to compare with: features alone weigh its neighbours.
        const float range_weight = (fb.valid[i] & kImagesValid) ? inv_range2 : 0.f;
        float num[kMaxImages][3] = {}, den[kMaxImages] = {}, scale[kMaxImages];
        for (int k = 0; k < count; ++k) {
          const float* p = images[k] + 3 * i;
          const float lum = std::max(0.f, (p[0] + p[1] + p[2]) * (1.f / 3.f)) + kRangeFloor;
          scale[k] = range_weight / (3.f * lum * lum);
        }
        for (int yy = std::max(0, y - r); yy <= std::min(H - 1, y + r); ++yy)
          for (int xx = std::max(0, x - r); xx <= std::min(W - 1, x + r); ++xx) {
            const size_t j = size_t(yy) * W + xx;
            if (!(fb.valid[j] & kImagesValid)) continue;
            if (!centre_features && j != i) continue;
            float df = 0.f;
            if (centre_features) {
              if (!(fb.valid[j] & kFeaturesValid)) continue;
              df = feature_distance(fb, i, j);
            }
            for (int k = 0; k < count; ++k) {
              const float *p = images[k] + 3 * i, *q = images[k] + 3 * j;
              float d = df;
              if (range_weight > 0.f) {
                const float d0 = q[0] - p[0], d1 = q[1] - p[1], d2 = q[2] - p[2];
                d += (d0 * d0 + d1 * d1 + d2 * d2) * scale[k];
              }
              const float w = std::exp(-0.5f * d);
              for (int c = 0; c < 3; ++c) num[k][c] += w * q[c];
              den[k] += w;
            }
          }
        for (int k = 0; k < count; ++k)
          for (int c = 0; c < 3; ++c)
            out[k][3 * i + c] = den[k] > 0.f ? num[k][c] / den[k] : images[k][3 * i + c];
      }
  });
}

}  // namespace gdpt::detail
