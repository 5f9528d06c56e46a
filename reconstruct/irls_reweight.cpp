#include "reconstruct/irls_reweight.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

namespace {

// The pass works row by row on planar copies of one row's term residuals (one array per
// channel), so that the per-pixel norms, square roots and divisions run as plain loops over
// floats, which the compiler vectorises; the interleaved inputs are read, and the residual
// written, once per value. Buffers are per thread and reused across passes.
struct RowBuffers {
  int width = 0;
  // e0 = primal - x, ex = dx - Dx x of the current row, per channel.
  std::vector<float> e0[3], ex[3];
  // Weighted residuals and data of the x edges, with one leading zero (the edge left of the
  // image): fx = wx ex, bx = wx dx.
  std::vector<float> fx[3], bx[3];
  // y edges of the current row and of the row above: fy = wy ey, by = wy dy, and ey / dy.
  std::vector<float> fy_row[3], by_row[3], fy_above[3], by_above[3], ey[3];
  std::vector<float> p0[3], gx[3];  // primal and dx (only for b)
  std::vector<float> wy_above, r[3];

  void resize(int W) {
    if (width >= W) return;
    width = W;
    const size_t n = size_t(W) + 1;
    for (int c = 0; c < 3; ++c)
      for (auto* v : {&e0[c], &ex[c], &fx[c], &bx[c], &fy_row[c], &by_row[c], &fy_above[c],
                      &by_above[c], &ey[c], &p0[c], &gx[c], &r[c]})
        v->assign(n, 0.f);
    wy_above.assign(n, 0.f);
  }
};

RowBuffers& row_buffers(int W) {
  thread_local RowBuffers b;
  b.resize(W);
  return b;
}

// Zero the weights of terms that are absent (missing data; the Neumann column / row are
// handled by the callers).
void drop_missing(const uint8_t* terms, uint8_t bit, int W, float* w) {
  if (!terms) return;
  for (int x = 0; x < W; ++x)
    if (!(terms[x] & bit)) w[x] = 0.f;
}

// Vertical edges of row y: wy, and fy = wy (dy - Dy x) and, with kRhs, by = wy dy per channel
// (planar), which the residual of this row and of the row below combine.
template <bool kRhs>
void vertical_edges(const IrlsData& d, float reg, const float* x, int y, RowBuffers& b, float* wy,
                    std::vector<float>* fy, std::vector<float>* by) {
  const int W = d.width;
  if (y == d.height - 1) {  // Neumann: no y edges below the last row
    std::fill_n(wy, W, 0.f);
    for (int c = 0; c < 3; ++c) {
      std::fill_n(fy[c].data(), W, 0.f);
      if constexpr (kRhs) std::fill_n(by[c].data(), W, 0.f);
    }
    return;
  }
  const size_t row = size_t(y) * W;
  const float* xr = x + 3 * row;
  const float* xd = xr + 3 * size_t(W);
  const float* g = d.gradient_y + 3 * row;
  float *e0 = b.ey[0].data(), *e1 = b.ey[1].data(), *e2 = b.ey[2].data();
  for (int i = 0; i < W; ++i) {
    e0[i] = g[3 * i] - (xd[3 * i] - xr[3 * i]);
    e1[i] = g[3 * i + 1] - (xd[3 * i + 1] - xr[3 * i + 1]);
    e2[i] = g[3 * i + 2] - (xd[3 * i + 2] - xr[3 * i + 2]);
  }
  for (int i = 0; i < W; ++i)
    wy[i] = 1.f / (std::sqrt(e0[i] * e0[i] + e1[i] * e1[i] + e2[i] * e2[i]) + reg);
  drop_missing(d.terms ? d.terms + row : nullptr, kDyTerm, W, wy);
  for (int c = 0; c < 3; ++c) {
    const float* e = b.ey[c].data();
    float* f = fy[c].data();
    for (int i = 0; i < W; ++i) f[i] = wy[i] * e[i];
  }
  if constexpr (kRhs)
    for (int c = 0; c < 3; ++c) {
      float* f = by[c].data();
      for (int i = 0; i < W; ++i) f[i] = wy[i] * g[3 * i + c];
    }
}

// w[i] = s2 / (s |e[.][i]|_RGB + reg) from planar e; a function of its own so that the loop
// vectorises (inside the pass's lambda it stayed scalar).
void norm_weights(const std::vector<float>* e, float s, float s2, float reg, int n, float* w) {
  const float *e0 = e[0].data(), *e1 = e[1].data(), *e2 = e[2].data();
  for (int i = 0; i < n; ++i)
    w[i] = s2 / (s * std::sqrt(e0[i] * e0[i] + e1[i] * e1[i] + e2[i] * e2[i]) + reg);
}

// Sum of v[i]^2 and of s[i] v[i]^2 over i < n, in double, in four fixed lanes (vectorisable,
// deterministic).
inline void add_squares(const float* v, const float* s, int n, double& vv, double& svv) {
  double a[4] = {}, b[4] = {};
  int i = 0;
  for (; i + 4 <= n; i += 4)
    for (int l = 0; l < 4; ++l) {
      const double q = double(v[i + l]) * v[i + l];
      a[l] += q;
      b[l] += q * s[i + l];
    }
  for (; i < n; ++i) {
    const double q = double(v[i]) * v[i];
    a[0] += q;
    b[0] += q * s[i];
  }
  vv += (a[0] + a[1]) + (a[2] + a[3]);
  svv += (b[0] + b[1]) + (b[2] + b[3]);
}

// The pass; kRhs: also b = W0 primal + Dx^T Wx dx + Dy^T Wy dy, for the sums |b_c|^2.
template <bool kRhs>
std::array<double, 9> reweight_pass(const IrlsData& d, float reg, const float* x,
                                    const IrlsWeights& out, float* r) {
  const int W = d.width, H = d.height;
  const float alpha = d.alpha, alpha2 = d.alpha * d.alpha;
  return parallel_rows_sum<9>(H, [&](int y0, int y1, std::array<double, 9>& sums) {
    RowBuffers& b = row_buffers(W);
    std::vector<float>*fy_above = b.fy_above, *by_above = b.by_above;
    std::vector<float>*fy_row = b.fy_row, *by_row = b.by_row;
    const float* wy_above = b.wy_above.data();
    if (y0 > 0) {
      vertical_edges<kRhs>(d, reg, x, y0 - 1, b, b.wy_above.data(), fy_above, by_above);
    } else {  // no row above the image: its terms are absent
      std::fill_n(b.wy_above.data(), W, 0.f);
      for (int c = 0; c < 3; ++c) {
        std::fill_n(fy_above[c].data(), W, 0.f);
        std::fill_n(by_above[c].data(), W, 0.f);
      }
    }

    for (int y = y0; y < y1; ++y) {
      const size_t row = size_t(y) * W;
      float* wy = out.wy + row;
      vertical_edges<kRhs>(d, reg, x, y, b, wy, fy_row, by_row);

      // --- Term residuals of the primal and of the x edges (e = data - operator applied to x),
      // planar. The last pixel has no right neighbour: its x edge gets weight 0 below.
      const float* xr = x + 3 * row;
      const float* pr = d.primal + 3 * row;
      const float* gr = d.gradient_x + 3 * row;
      float *e00 = b.e0[0].data(), *e01 = b.e0[1].data(), *e02 = b.e0[2].data();
      float *ex0 = b.ex[0].data(), *ex1 = b.ex[1].data(), *ex2 = b.ex[2].data();
      for (int i = 0; i < W - 1; ++i) {
        const float* xi = xr + 3 * i;
        const float *pi = pr + 3 * i, *gi = gr + 3 * i;
        e00[i] = pi[0] - xi[0];
        e01[i] = pi[1] - xi[1];
        e02[i] = pi[2] - xi[2];
        ex0[i] = gi[0] - (xi[3] - xi[0]);
        ex1[i] = gi[1] - (xi[4] - xi[1]);
        ex2[i] = gi[2] - (xi[5] - xi[2]);
      }
      for (int c = 0; c < 3; ++c) {
        b.e0[c][W - 1] = pr[3 * (W - 1) + c] - xr[3 * (W - 1) + c];
        b.ex[c][W - 1] = 0.f;
      }
      if constexpr (kRhs)
        for (int c = 0; c < 3; ++c) {
          float *p0 = b.p0[c].data(), *gx = b.gx[c].data();
          for (int i = 0; i < W; ++i) {
            p0[i] = pr[3 * i + c];
            gx[i] = gr[3 * i + c];
          }
        }

      // --- Weights and the Jacobi diagonal.
      float* w0 = out.w0 + row;
      float* wx = out.wx + row;
      float* inv = out.inv_diagonal + row;
      norm_weights(b.e0, alpha, alpha2, reg, W, w0);
      norm_weights(b.ex, 1.f, 1.f, reg, W, wx);
      wx[W - 1] = 0.f;
      drop_missing(d.terms ? d.terms + row : nullptr, kPrimalTerm, W, w0);
      drop_missing(d.terms ? d.terms + row : nullptr, kDxTerm, W, wx);
      inv[0] = w0[0] + wx[0] + wy[0] + wy_above[0];
      for (int i = 1; i < W; ++i) inv[i] = w0[i] + wx[i] + wx[i - 1] + wy[i] + wy_above[i];
      for (int i = 0; i < W; ++i) inv[i] = inv[i] > 0.f ? 1.f / inv[i] : 0.f;

      // --- Residual r = W0 e0 - fx + fx_left - fy + fy_above per channel (b likewise), its
      // sums, then written interleaved.
      for (int c = 0; c < 3; ++c) {
        float* fx = b.fx[c].data() + 1;  // fx[-1] = 0: no edge left of the image
        const float* ex = b.ex[c].data();
        for (int i = 0; i < W; ++i) fx[i] = wx[i] * ex[i];
        const float* e0 = b.e0[c].data();
        const float *fy = fy_row[c].data(), *fya = fy_above[c].data();
        float* rc = b.r[c].data();
        for (int i = 0; i < W; ++i) rc[i] = w0[i] * e0[i] - fx[i] + fx[i - 1] - fy[i] + fya[i];
        add_squares(rc, inv, W, sums[c], sums[6 + c]);
        if constexpr (kRhs) {
          float* bx = b.bx[c].data() + 1;
          const float* g = b.gx[c].data();
          for (int i = 0; i < W; ++i) bx[i] = wx[i] * g[i];
          const float *p0 = b.p0[c].data(), *by = by_row[c].data(), *bya = by_above[c].data();
          float* bc = b.e0[c].data();  // e0 is no longer needed: b of the row goes there
          for (int i = 0; i < W; ++i) bc[i] = w0[i] * p0[i] - bx[i] + bx[i - 1] - by[i] + bya[i];
          double unused = 0.0;
          add_squares(bc, inv, W, sums[3 + c], unused);
        }
      }
      float* rr = r + 3 * row;
      const float *r0 = b.r[0].data(), *r1 = b.r[1].data(), *r2 = b.r[2].data();
      for (int i = 0; i < W; ++i) {
        rr[3 * i] = r0[i];
        rr[3 * i + 1] = r1[i];
        rr[3 * i + 2] = r2[i];
      }

      std::swap(fy_above, fy_row);
      std::swap(by_above, by_row);
      wy_above = wy;
    }
  });
}

}  // namespace

CgStart irls_reweight(const IrlsData& d, float reg, const float* x, const IrlsWeights& out,
                      float* r, bool with_rhs) {
  const auto s =
      with_rhs ? reweight_pass<true>(d, reg, x, out, r) : reweight_pass<false>(d, reg, x, out, r);
  CgStart start;
  for (int c = 0; c < 3; ++c) {
    start.rr[c] = s[c];
    start.bb[c] = s[3 + c];
    start.rz[c] = s[6 + c];
  }
  return start;
}

}  // namespace gdpt::detail
