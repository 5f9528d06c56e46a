#include "reconstruct/feature_buffers.h"

#include <algorithm>
#include <cmath>
#include <memory>

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
  const size_t row = size_t(W) * C;
  // Rows: window sums from prefix sums; the mean's divisions are applied once, at the end.
  // Written in full by the row pass: left uninitialised (zeroing it would cost a full pass).
  const std::unique_ptr<float[]> rows(new float[row * height]);
  std::vector<double> inv_x(W);
  for (int x = 0; x < W; ++x)
    inv_x[x] = 1.0 / double(std::min(W, x + radius + 1) - std::max(0, x - radius));
  parallel_rows(height, [&](int y0, int y1) {
    std::vector<double> prefix(size_t(W + 1) * C);
    for (int y = y0; y < y1; ++y) {
      const float* s = src + size_t(y) * row;
      for (int c = 0; c < C; ++c) prefix[c] = 0.0;
      for (size_t i = 0; i < row; ++i) prefix[i + C] = prefix[i] + s[i];
      float* d = rows.get() + size_t(y) * row;
      for (int x = 0; x < W; ++x) {
        const size_t lo = size_t(std::max(0, x - radius)) * C,
                     hi = size_t(std::min(W, x + radius + 1)) * C;
        for (int c = 0; c < C; ++c) d[size_t(x) * C + c] = float(prefix[hi + c] - prefix[lo + c]);
      }
    }
  });
  // Columns: a running sum down each chunk (in double, so that adding and removing rows leaves
  // no drift); chunks start afresh, so the result does not depend on the thread count.
  parallel_rows(height, [&](int y0, int y1) {
    std::vector<double> sum(row, 0.0);
    auto add = [&](int yy, double sign) {
      const float* r = rows.get() + size_t(yy) * row;
      for (size_t i = 0; i < row; ++i) sum[i] += sign * r[i];
    };
    int lo = std::max(0, y0 - radius), hi = std::min(height, y0 + radius + 1);
    for (int yy = lo; yy < hi; ++yy) add(yy, 1.0);
    for (int y = y0; y < y1; ++y) {
      const int nlo = std::max(0, y - radius), nhi = std::min(height, y + radius + 1);
      for (; lo < nlo; ++lo) add(lo, -1.0);
      for (; hi < nhi; ++hi) add(hi, 1.0);
      const double inv_y = 1.0 / double(hi - lo);
      float* d = dst + size_t(y) * row;
      for (int x = 0; x < W; ++x)
        for (int c = 0; c < C; ++c) {
          const size_t i = size_t(x) * C + c;
          d[i] = float(sum[i] * (inv_y * inv_x[x]));
        }
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
