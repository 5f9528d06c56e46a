#include "reconstruct/feature_buffers.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

namespace {

bool finite_n(const float* v, int n) {
  for (int c = 0; c < n; ++c)
    if (!std::isfinite(v[c])) return false;
  return true;
}

struct FeatureSource {
  const float* values;
  const float* variance;  // may be null
  int channels;
};

// The features present, in the fixed order guide, albedo, normal, depth.
std::vector<FeatureSource> feature_sources(const ReconstructionInput& in, const float* guide) {
  std::vector<FeatureSource> s;
  if (guide) s.push_back({guide, nullptr, 3});
  if (in.albedo) s.push_back({in.albedo, in.albedo_variance, 3});
  if (in.normal) s.push_back({in.normal, in.normal_variance, 3});
  if (in.depth) s.push_back({in.depth, in.depth_variance, 1});
  return s;
}

// Halves and their variances, masked; fills valid's kHalvesValid bit.
void prepare_halves(const ReconstructionInput& in, FeatureBuffers& fb) {
  const int W = fb.width;
  const size_t n = size_t(W) * fb.height;
  fb.a.assign(3 * n, 0.f);
  fb.b.assign(3 * n, 0.f);
  fb.half_var.assign(3 * n, 0.f);
  const bool given = in.variance_a && in.variance_b;
  parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      const float *pa = in.primal_a + 3 * i, *pb = in.primal_b + 3 * i;
      bool ok = finite_n(pa, 3) && finite_n(pb, 3);
      if (given)
        ok = ok && finite_n(in.variance_a + 3 * i, 3) && finite_n(in.variance_b + 3 * i, 3);
      if (!ok) continue;
      fb.valid[i] |= kHalvesValid;
      for (int c = 0; c < 3; ++c) {
        fb.a[3 * i + c] = pa[c];
        fb.b[3 * i + c] = pb[c];
        const float d = pa[c] - pb[c];
        // E[(A - B)^2] = Var A + Var B for independent halves.
        fb.half_var[3 * i + c] = given ? 0.5f * (std::max(0.f, in.variance_a[3 * i + c]) +
                                                 std::max(0.f, in.variance_b[3 * i + c]))
                                       : 0.5f * d * d;
      }
    }
  });
}

// The 3x3 patch means of both halves and their variances (for the NLM weights).
void prepare_patches(const ReconstructionInput& in, FeatureBuffers& fb) {
  const int W = fb.width, H = fb.height;
  const size_t n = size_t(W) * H;
  fb.smooth_a.resize(3 * n);
  fb.smooth_b.resize(3 * n);
  box_filter(fb.a.data(), 3, W, H, 1, fb.smooth_a.data());
  box_filter(fb.b.data(), 3, W, H, 1, fb.smooth_b.data());
  // Per-half variance: given, or (A - B)^2 / 2 averaged over 5x5 (a single pixel's is too noisy
  // to scale a distance by).
  std::vector<float> va(3 * n), vb(3 * n);
  const bool given = in.variance_a && in.variance_b;
  parallel_rows(H, [&](int y0, int y1) {
    for (size_t i = 3 * size_t(y0) * W; i < 3 * size_t(y1) * W; ++i) {
      const bool ok = fb.valid[i / 3] & kHalvesValid;
      va[i] = ok ? (given ? std::max(0.f, in.variance_a[i]) : fb.half_var[i]) : 0.f;
      vb[i] = ok ? (given ? std::max(0.f, in.variance_b[i]) : fb.half_var[i]) : 0.f;
    }
  });
  fb.patch_var_a.resize(3 * n);
  fb.patch_var_b.resize(3 * n);
  box_filter(va.data(), 3, W, H, given ? 1 : 2, fb.patch_var_a.data());
  box_filter(vb.data(), 3, W, H, given ? 1 : 2, fb.patch_var_b.data());
  // A 3x3 mean of independent pixels has a ninth of their variance.
  parallel_rows(H, [&](int y0, int y1) {
    for (size_t i = 3 * size_t(y0) * W; i < 3 * size_t(y1) * W; ++i) {
      fb.patch_var_a[i] *= 1.f / 9.f;
      fb.patch_var_b[i] *= 1.f / 9.f;
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

FeatureBuffers prepare_feature_buffers(const ReconstructionInput& in, const float* guide) {
  FeatureBuffers fb;
  fb.width = in.width;
  fb.height = in.height;
  const int W = in.width, H = in.height;
  const size_t n = size_t(W) * H;
  fb.valid.assign(n, 0);
  prepare_halves(in, fb);

  // Per feature channel: validity first, then sum and sum of squares over valid pixels.
  const std::vector<FeatureSource> sources = feature_sources(in, guide);
  parallel_rows(H, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      bool ok = true;
      for (const auto& s : sources) {
        ok = ok && finite_n(s.values + s.channels * i, s.channels);
        if (s.variance) ok = ok && finite_n(s.variance + s.channels * i, s.channels);
      }
      if (ok) fb.valid[i] |= kFeaturesValid;
    }
  });
  struct Channel {
    const float* values;
    const float* variance;
    int stride, offset;
    bool guide;
  };
  std::vector<Channel> channels;
  for (const auto& s : sources)
    for (int c = 0; c < s.channels; ++c)
      channels.push_back({s.values, s.variance, s.channels, c, s.values == guide});
  const auto moments = parallel_rows_sum<2 * kMaxFeatures + 1>(
      H, [&](int y0, int y1, std::array<double, 2 * kMaxFeatures + 1>& m) {
        for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
          if (!(fb.valid[i] & kFeaturesValid)) continue;
          m[2 * kMaxFeatures] += 1;
          for (size_t k = 0; k < channels.size(); ++k) {
            const double v = channels[k].values[channels[k].stride * i + channels[k].offset];
            m[2 * k] += v;
            m[2 * k + 1] += v * v;
          }
        }
      });
  // Keep the channels that vary; scale each to unit standard deviation over the image.
  const double count = std::max(1.0, moments[2 * kMaxFeatures]);
  std::vector<Channel> kept;
  std::vector<float> scale;
  for (size_t k = 0; k < channels.size(); ++k) {
    const double mean = moments[2 * k] / count;
    const double var = std::max(0.0, moments[2 * k + 1] / count - mean * mean);
    if (!(var > 1e-12 * (1.0 + mean * mean))) continue;
    kept.push_back(channels[k]);
    scale.push_back(float(1.0 / std::sqrt(var)));
  }
  fb.count = int(kept.size());
  const int d = fb.count;
  for (int k = 0; k < d; ++k) {
    fb.guide_colour[k] = kept[k].guide ? kept[k].offset : -1;
    fb.guide_slope[k] = 1.f / scale[k];
  }
  fb.features.assign(n * d, 0.f);
  fb.noise.assign(n * d, 0.f);
  parallel_rows(H, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      if (!(fb.valid[i] & kFeaturesValid)) continue;
      for (int k = 0; k < d; ++k) {
        const Channel& ch = kept[k];
        const size_t at = ch.stride * i + ch.offset;
        fb.features[d * i + k] = ch.values[at] * scale[k];
        if (ch.variance) fb.noise[d * i + k] = std::max(0.f, ch.variance[at]) * scale[k] * scale[k];
      }
    }
  });
  prepare_patches(in, fb);
  for (size_t i = 0; i < n; ++i)
    fb.missing +=
        (fb.valid[i] & (kHalvesValid | kFeaturesValid)) != (kHalvesValid | kFeaturesValid);
  return fb;
}

}  // namespace gdpt::detail
