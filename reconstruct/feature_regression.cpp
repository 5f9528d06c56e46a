#include "reconstruct/feature_regression.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

namespace {

constexpr int kMaxD = kMaxFeatures + 1;  // features + intercept
constexpr int kCols = 16;                // a sample's [1, features, RGB], padded for SIMD
// Pull of a feature's slope towards zero per unit weight, in units of the feature's spread over
// the image: a feature that barely varies inside the window says nothing.
constexpr float kFeatureRidge = 1e-3f;
constexpr uint8_t kUsable = kHalvesValid | kFeaturesValid;
// The pixel's own value joins the blend with this weight (the four centres' weights sum to at
// most 1): where no centre's model fits the pixel (structure finer than the centre grid that no
// feature explains), the result falls back to the unbiased noisy value instead of a wrong one.
constexpr float kSelfWeight = 0.01f;

// exp(-x) for x >= 0 within 0.3%: 2^-t from a quadratic on the fraction and the exponent bits.
// The weights need neither more accuracy nor the libm call's cost (two per sample and pixel).
inline float exp_neg(float x) {
  const float t = -std::min(x * 1.4426950f, 125.f);
  const float i = std::floor(t), f = t - i;
  const float p = 1.f + f * (0.6565f + f * 0.3435f);
  int32_t bits;
  std::memcpy(&bits, &p, sizeof bits);
  bits += int32_t(i) * (1 << 23);
  float r;
  std::memcpy(&r, &bits, sizeof r);
  return r;
}

// NLM weight of pixel q seen from pixel p: the squared difference of the 3x3 patch means, less
// its expected noise, relative to that noise (NFOR's form, patch means for speed).
inline float nlm_weight(const float* mean, const float* var, size_t p, size_t q, float k2) {
  float d = 0.f;
  for (int c = 0; c < 3; ++c) {
    const float mp = mean[3 * p + c], mq = mean[3 * q + c];
    const float diff = mp - mq, v = var[3 * p + c] + var[3 * q + c];
    d += (diff * diff - v) / (k2 * v + 1e-4f * (mp * mp + mq * mq) + 1e-12f);
  }
  return exp_neg(std::max(0.f, d * (1.f / 3.f)));
}

struct CenterGrid {
  int width, height, nx, ny;
  CenterGrid(int W, int H)
      : width(W),
        height(H),
        nx((W - 1 + kCenterSpacing - 1) / kCenterSpacing + 1),
        ny((H - 1 + kCenterSpacing - 1) / kCenterSpacing + 1) {}
  int x(int i) const { return std::min(i * kCenterSpacing, width - 1); }
  int y(int j) const { return std::min(j * kCenterSpacing, height - 1); }
};

// Solves the D x D system in place by Cholesky (double); false if not positive definite.
bool cholesky_solve(double (&a)[kMaxD][kMaxD], double (&rhs)[kMaxD][3], int D) {
  for (int j = 0; j < D; ++j) {
    double s = a[j][j];
    for (int k = 0; k < j; ++k) s -= a[j][k] * a[j][k];
    if (!(s > 0.0)) return false;
    a[j][j] = std::sqrt(s);
    for (int i = j + 1; i < D; ++i) {
      double t = a[i][j];
      for (int k = 0; k < j; ++k) t -= a[i][k] * a[j][k];
      a[i][j] = t / a[j][j];
    }
  }
  for (int c = 0; c < 3; ++c) {
    for (int i = 0; i < D; ++i) {
      double t = rhs[i][c];
      for (int k = 0; k < i; ++k) t -= a[i][k] * rhs[k][c];
      rhs[i][c] = t / a[i][i];
    }
    for (int i = D - 1; i >= 0; --i) {
      double t = rhs[i][c];
      for (int k = i + 1; k < D; ++k) t -= a[k][i] * rhs[k][c];
      rhs[i][c] = t / a[i][i];
    }
  }
  return true;
}

struct FilterArgs {
  const FeatureBuffers& fb;
  const float* target;
  const float* weight_mean;
  const float* weight_var;
  const CandidateFilter& filter;
};

// The weighted normal equations of a centre's window: rows [1, f - f_c] against [1, f - f_c, RGB].
struct WindowSums {
  alignas(64) float m[kMaxD][kCols] = {};
  float wsum = 0.f;
};

WindowSums accumulate_window(const FilterArgs& a, int cx, int cy) {
  const FeatureBuffers& fb = a.fb;
  const int W = fb.width, H = fb.height, d = fb.count, D = d + 1, s = a.filter.stride;
  const size_t c = size_t(cy) * W + cx;
  const float* fc = fb.features.data() + d * c;
  const bool center_ok = fb.valid[c] & kHalvesValid;
  const float k2 = a.filter.bandwidth * a.filter.bandwidth;
  WindowSums ws;
  for (int v = -kWindowRadius; v <= kWindowRadius; ++v) {
    const int y = cy + v * s;
    if (y < 0 || y >= H) continue;
    for (int u = -kWindowRadius; u <= kWindowRadius; ++u) {
      const int x = cx + u * s;
      if (x < 0 || x >= W) continue;
      const size_t q = size_t(y) * W + x;
      if ((fb.valid[q] & kUsable) != kUsable) continue;
      const float w = center_ok ? nlm_weight(a.weight_mean, a.weight_var, c, q, k2) : 1.f;
      if (w < 1e-6f) continue;
      alignas(64) float z[kCols] = {};
      z[0] = 1.f;
      const float* fq = fb.features.data() + d * q;
      for (int k = 0; k < d; ++k) z[1 + k] = fq[k] - fc[k];
      for (int ch = 0; ch < 3; ++ch) z[D + ch] = a.target[3 * q + ch];
      for (int j = 0; j < D; ++j) {
        const float wz = w * z[j];
        for (int k = 0; k < kCols; ++k) ws.m[j][k] += wz * z[k];
      }
      ws.wsum += w;
    }
  }
  return ws;
}

// Solves a centre's ridge regression for beta (D x 3), colour = beta_0 + beta_k (f - f_c);
// without the guide, its slopes are fixed at zero.
void solve_model(const FilterArgs& a, const WindowSums& ws, size_t c, bool use_guide, float* beta) {
  const FeatureBuffers& fb = a.fb;
  const int d = fb.count, D = d + 1;
  double lhs[kMaxD][kMaxD] = {}, rhs[kMaxD][3] = {};
  for (int j = 0; j < D; ++j) {
    for (int k = 0; k < D; ++k) lhs[j][k] = ws.m[j][k];
    for (int ch = 0; ch < 3; ++ch) rhs[j][ch] = ws.m[j][D + ch];
  }
  lhs[0][0] += 1e-6 * ws.wsum;
  const float* noise = fb.noise.data() + d * c;
  for (int k = 0; k < d; ++k) {
    const int colour = fb.guide_colour[k];
    if (colour >= 0 && !use_guide) {
      for (int j = 0; j < D; ++j) lhs[1 + k][j] = lhs[j][1 + k] = 0.0;
      for (int ch = 0; ch < 3; ++ch) rhs[1 + k][ch] = 0.0;
      lhs[1 + k][1 + k] = 1.0;
      continue;
    }
    const double ridge = ws.wsum * ((colour >= 0 ? kGuideRidge : kFeatureRidge) + noise[k]);
    lhs[1 + k][1 + k] += ridge;
    if (colour >= 0) rhs[1 + k][colour] += ridge * fb.guide_slope[k];
  }
  double chol[kMaxD][kMaxD];
  std::copy(&lhs[0][0], &lhs[0][0] + kMaxD * kMaxD, &chol[0][0]);
  double sol[kMaxD][3];
  std::copy(&rhs[0][0], &rhs[0][0] + kMaxD * 3, &sol[0][0]);
  if (!cholesky_solve(chol, sol, D)) {
    // Degenerate window: the weighted mean.
    for (int j = 0; j < D; ++j)
      for (int ch = 0; ch < 3; ++ch) sol[j][ch] = j == 0 ? rhs[0][ch] / lhs[0][0] : 0.0;
  }
  for (int j = 0; j < D; ++j)
    for (int ch = 0; ch < 3; ++ch) beta[3 * j + ch] = float(sol[j][ch]);
}

// Blends the models of the four centres around every pixel of rows [y0, y1); models and outputs
// per variant (without, with the guide).
void apply_models(const FilterArgs& a, const CenterGrid& g, int variants,
                  const std::vector<float>& betas, const std::vector<uint8_t>& fitted, int y0,
                  int y1, float* const* out) {
  const FeatureBuffers& fb = a.fb;
  const int W = fb.width, d = fb.count;
  const float k2 = a.filter.bandwidth * a.filter.bandwidth;
  auto cell = [](int p, int n, int limit, int& i0, float& t) {
    i0 = std::min(p / kCenterSpacing, std::max(0, n - 2));
    const int p0 = std::min(i0 * kCenterSpacing, limit - 1);
    const int p1 = std::min((i0 + 1) * kCenterSpacing, limit - 1);
    t = p1 > p0 ? float(p - p0) / float(p1 - p0) : 0.f;
  };
  for (int y = y0; y < y1; ++y) {
    int j0;
    float ty;
    cell(y, g.ny, g.height, j0, ty);
    for (int x = 0; x < W; ++x) {
      int i0;
      float tx;
      cell(x, g.nx, g.width, i0, tx);
      const size_t p = size_t(y) * W + x;
      const bool p_features = fb.valid[p] & kFeaturesValid, p_halves = fb.valid[p] & kHalvesValid;
      float acc[2][3] = {}, wsum = 0.f;
      for (int corner = 0; corner < 4; ++corner) {
        const int i = std::min(i0 + (corner & 1), g.nx - 1),
                  j = std::min(j0 + (corner >> 1), g.ny - 1);
        const float bil = ((corner & 1) ? tx : 1.f - tx) * ((corner >> 1) ? ty : 1.f - ty);
        const size_t ci = size_t(j) * g.nx + i;
        if (bil <= 0.f || !fitted[ci]) continue;
        const size_t c = size_t(g.y(j)) * W + g.x(i);
        const float nlm = p_halves && (fb.valid[c] & kHalvesValid)
                              ? nlm_weight(a.weight_mean, a.weight_var, c, p, k2)
                              : 1.f;
        const float w = bil * std::max(nlm, 1e-4f);
        wsum += w;
        for (int v = 0; v < variants; ++v) {
          const float* beta = betas.data() + (ci * variants + v) * kMaxD * 3;
          float pred[3] = {beta[0], beta[1], beta[2]};
          if (p_features) {
            const float *fp = fb.features.data() + d * p, *fc = fb.features.data() + d * c;
            for (int k = 0; k < d; ++k) {
              const float df = fp[k] - fc[k];
              for (int ch = 0; ch < 3; ++ch) pred[ch] += beta[3 * (1 + k) + ch] * df;
            }
          }
          for (int ch = 0; ch < 3; ++ch) acc[v][ch] += w * pred[ch];
        }
      }
      if (p_halves) {
        for (int v = 0; v < variants; ++v)
          for (int ch = 0; ch < 3; ++ch) acc[v][ch] += kSelfWeight * a.target[3 * p + ch];
        wsum += kSelfWeight;
      }
      for (int v = 0; v < variants; ++v)
        for (int ch = 0; ch < 3; ++ch) out[v][3 * p + ch] = wsum > 0.f ? acc[v][ch] / wsum : 0.f;
    }
  }
}

}  // namespace

bool has_guide(const FeatureBuffers& fb) {
  for (int k = 0; k < fb.count; ++k)
    if (fb.guide_colour[k] >= 0) return true;
  return false;
}

void cross_filter_half(const FeatureBuffers& fb, const float* target, const float* weight_mean,
                       const float* weight_var, const CandidateFilter& filter, float* const* out) {
  const FilterArgs a{fb, target, weight_mean, weight_var, filter};
  const CenterGrid g(fb.width, fb.height);
  const int variants = has_guide(fb) ? 2 : 1;
  std::vector<float> betas(size_t(g.nx) * g.ny * variants * kMaxD * 3, 0.f);
  std::vector<uint8_t> fitted(size_t(g.nx) * g.ny, 0);
  parallel_rows(g.ny, [&](int j0, int j1) {
    for (int j = j0; j < j1; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const size_t ci = size_t(j) * g.nx + i;
        const WindowSums ws = accumulate_window(a, g.x(i), g.y(j));
        if (!(ws.wsum > 0.f)) continue;
        fitted[ci] = 1;
        const size_t c = size_t(g.y(j)) * fb.width + g.x(i);
        for (int v = 0; v < variants; ++v)
          solve_model(a, ws, c, v == 1, betas.data() + (ci * variants + v) * kMaxD * 3);
      }
  });
  parallel_rows(fb.height,
                [&](int y0, int y1) { apply_models(a, g, variants, betas, fitted, y0, y1, out); });
}

}  // namespace gdpt::detail
