#include "reconstruct/feature_buffers.h"

#include <algorithm>
#include <cmath>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

namespace {

bool finite_n(const float* v, int n) {
  for (int c = 0; c < n; ++c)
    if (!std::isfinite(v[c])) return false;
  return true;
}

// Copies `n`-channel values and variances into the feature planes from plane `offset`;
// clears kFeaturesValid where a value or variance is not finite.
void copy_feature(const float* values, const float* variance, int n, int offset,
                  FeatureBuffers& fb) {
  if (!values) return;
  fb.features += n;
  const int W = fb.width;
  const size_t pixels = size_t(W) * fb.height;
  parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      const float* v = values + size_t(n) * i;
      const float* var = variance ? variance + size_t(n) * i : nullptr;
      if (!finite_n(v, n) || (var && !finite_n(var, n))) {
        fb.valid[i] &= uint8_t(~kFeaturesValid);
        continue;
      }
      for (int c = 0; c < n; ++c) {
        fb.feature[size_t(offset + c) * pixels + i] = v[c];
        fb.feature_var[size_t(offset + c) * pixels + i] = var ? std::max(0.f, var[c]) : 0.f;
      }
    }
  });
}

}  // namespace

void box_filter(const float* src, int channels, int width, int height, int radius, float* dst) {
  const int W = width, C = channels;
  std::vector<float> rows(size_t(W) * height * C);
  parallel_rows(height, [&](int y0, int y1) {
    std::vector<double> prefix(size_t(W + 1) * C);
    for (int y = y0; y < y1; ++y) {
      const float* s = src + size_t(y) * W * C;
      for (int c = 0; c < C; ++c) prefix[c] = 0.0;
      for (int x = 0; x < W; ++x)
        for (int c = 0; c < C; ++c)
          prefix[size_t(x + 1) * C + c] = prefix[size_t(x) * C + c] + s[x * C + c];
      float* d = rows.data() + size_t(y) * W * C;
      for (int x = 0; x < W; ++x) {
        const int lo = std::max(0, x - radius), hi = std::min(W, x + radius + 1);
        const double inv = 1.0 / (hi - lo);
        for (int c = 0; c < C; ++c)
          d[x * C + c] = float((prefix[size_t(hi) * C + c] - prefix[size_t(lo) * C + c]) * inv);
      }
    }
  });
  parallel_rows(height, [&](int y0, int y1) {
    std::vector<float> sum(size_t(W) * C);
    for (int y = y0; y < y1; ++y) {
      const int lo = std::max(0, y - radius), hi = std::min(height, y + radius + 1);
      std::fill(sum.begin(), sum.end(), 0.f);
      for (int yy = lo; yy < hi; ++yy) {
        const float* r = rows.data() + size_t(yy) * W * C;
        for (size_t i = 0; i < size_t(W) * C; ++i) sum[i] += r[i];
      }
      const float inv = 1.f / float(hi - lo);
      float* d = dst + size_t(y) * W * C;
      for (size_t i = 0; i < size_t(W) * C; ++i) d[i] = sum[i] * inv;
    }
  });
}

FeatureBuffers prepare_feature_buffers(const ReconstructionInput& in, const float* a,
                                       const float* b, const float* all, const float* variance_a,
                                       const float* variance_b) {
  FeatureBuffers fb;
  fb.width = in.width;
  fb.height = in.height;
  const int W = in.width;
  const size_t n = size_t(W) * in.height;
  fb.a.assign(3 * n, 0.f);
  fb.b.assign(3 * n, 0.f);
  fb.all.assign(3 * n, 0.f);
  fb.half_var.assign(3 * n, 0.f);
  fb.valid.assign(n, kFeaturesValid);
  const bool given = variance_a && variance_b;
  parallel_rows(in.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      const size_t k = 3 * i;
      bool ok = finite_n(a + k, 3) && finite_n(b + k, 3) && finite_n(all + k, 3);
      if (given) ok = ok && finite_n(variance_a + k, 3) && finite_n(variance_b + k, 3);
      if (!ok) continue;
      fb.valid[i] |= kImagesValid;
      for (int c = 0; c < 3; ++c) {
        fb.a[k + c] = a[k + c];
        fb.b[k + c] = b[k + c];
        fb.all[k + c] = all[k + c];
        const float d = a[k + c] - b[k + c];
        // E[(A - B)^2] = Var A + Var B for independent halves.
        fb.half_var[k + c] =
            given ? 0.5f * (std::max(0.f, variance_a[k + c]) + std::max(0.f, variance_b[k + c]))
                  : 0.5f * d * d;
      }
    }
  });
  fb.feature.assign(kFeatureChannels * n, 0.f);
  fb.feature_var.assign(kFeatureChannels * n, 0.f);
  copy_feature(in.albedo, in.albedo_variance, 3, 0, fb);
  copy_feature(in.normal, in.normal_variance, 3, 3, fb);
  copy_feature(in.depth, in.depth_variance, 1, 6, fb);
  for (size_t i = 0; i < n; ++i) fb.missing += fb.valid[i] != (kImagesValid | kFeaturesValid);
  return fb;
}

}  // namespace gdpt::detail
