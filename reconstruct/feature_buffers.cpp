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

// Writes `n`-channel values and variances to the feature planes from plane `offset` (0 for an
// absent feature); where a value or variance is not finite, 0 and kFeaturesValid cleared.
void copy_feature(const float* values, const float* variance, int n, int offset,
                  FeatureBuffers& fb) {
  if (values) fb.features += n;
  const int W = fb.width;
  const size_t pixels = size_t(W) * fb.height;
  parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      const float* v = values ? values + size_t(n) * i : nullptr;
      const float* var = variance && values ? variance + size_t(n) * i : nullptr;
      const bool ok = v && finite_n(v, n) && (!var || finite_n(var, n));
      if (v && !ok) fb.valid[i] &= uint8_t(~kFeaturesValid);
      for (int c = 0; c < n; ++c) {
        fb.feature[size_t(offset + c) * pixels + i] = ok ? v[c] : 0.f;
        fb.feature_var[size_t(offset + c) * pixels + i] = ok && var ? std::max(0.f, var[c]) : 0.f;
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
  FreshHugeVector<float> rows(row * height);
  std::vector<double> inv_x(W);
  for (int x = 0; x < W; ++x)
    inv_x[x] = 1.0 / double(std::min(W, x + radius + 1) - std::max(0, x - radius));
  parallel_rows(height, [&](int y0, int y1) {
    std::vector<double> prefix(size_t(W + 1) * C);
    for (int y = y0; y < y1; ++y) {
      const float* s = src + size_t(y) * row;
      for (int c = 0; c < C; ++c) prefix[c] = 0.0;
      for (size_t i = 0; i < row; ++i) prefix[i + C] = prefix[i] + s[i];
      float* d = rows.data() + size_t(y) * row;
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
      const float* r = rows.data() + size_t(yy) * row;
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
  // Unwritten until the parallel passes below write every element (fresh pages, no zero fill).
  for (FreshHugeVector<float>* v : {&fb.a, &fb.b, &fb.all, &fb.half_var}) v->resize(3 * n);
  fb.valid.resize(n);
  fb.feature.resize(kFeatureChannels * n);
  fb.feature_var.resize(kFeatureChannels * n);
  const bool given = variance_a && variance_b;
  parallel_rows(in.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      const size_t k = 3 * i;
      bool ok = finite_n(a + k, 3) && finite_n(b + k, 3) && finite_n(all + k, 3);
      if (given) ok = ok && finite_n(variance_a + k, 3) && finite_n(variance_b + k, 3);
      fb.valid[i] = ok ? kFeaturesValid | kImagesValid : kFeaturesValid;
      for (int c = 0; c < 3; ++c) {
        const float d = a[k + c] - b[k + c];
        // E[(A - B)^2] = Var A + Var B for independent halves.
        const float var =
            given ? 0.5f * (std::max(0.f, variance_a[k + c]) + std::max(0.f, variance_b[k + c]))
                  : 0.5f * d * d;
        fb.a[k + c] = ok ? a[k + c] : 0.f;
        fb.b[k + c] = ok ? b[k + c] : 0.f;
        fb.all[k + c] = ok ? all[k + c] : 0.f;
        fb.half_var[k + c] = ok ? var : 0.f;
      }
    }
  });
  copy_feature(in.albedo, in.albedo_variance, 3, 0, fb);
  copy_feature(in.normal, in.normal_variance, 3, 3, fb);
  copy_feature(in.depth, in.depth_variance, 1, 6, fb);
  for (size_t i = 0; i < n; ++i) fb.missing += fb.valid[i] != (kImagesValid | kFeaturesValid);
  return fb;
}

}  // namespace gdpt::detail
