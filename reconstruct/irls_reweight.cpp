#include "reconstruct/irls_reweight.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

namespace {

// The terms of pixel (x, y), with the Neumann column / row dropped.
inline uint8_t terms_at(const IrlsData& d, size_t i, int x, int y) {
  uint8_t t = d.terms ? d.terms[i] : uint8_t(kAllTerms);
  if (x == d.width - 1) t &= uint8_t(~kDxTerm);
  if (y == d.height - 1) t &= uint8_t(~kDyTerm);
  return t;
}

// Per-thread row buffers: the y-fluxes of the current row and of the row above, and the weights
// of the row above a chunk (that row belongs to the chunk above, possibly being written by
// another thread, so each chunk recomputes its own copy).
struct RowBuffers {
  std::vector<float> fy_above, by_above, fy_row, by_row, wy_above;
};

RowBuffers& row_buffers(int W) {
  thread_local RowBuffers b;
  const size_t n = size_t(3) * W;
  if (b.fy_above.size() < n) {
    for (auto* v : {&b.fy_above, &b.by_above, &b.fy_row, &b.by_row}) v->resize(n);
    b.wy_above.resize(size_t(W));
  }
  return b;
}

// Vertical edges of row y: wy, and the weighted residual fy = wy (dy - Dy x) and data
// by = wy dy per channel, which the residual of this row and of the row below combine.
void vertical_edges(const IrlsData& d, float reg, const float* x, int y, float* wy, float* fy,
                    float* by) {
  const int W = d.width;
  const size_t row = size_t(y) * W, down = size_t(std::min(y + 1, d.height - 1)) * W;
  for (int xx = 0; xx < W; ++xx) {
    const size_t i = row + xx, id = down + xx;
    const float* g = d.gradient_y + 3 * i;
    float e[3], n2 = 0.f;
    for (int c = 0; c < 3; ++c) {
      e[c] = g[c] - (x[3 * id + c] - x[3 * i + c]);
      n2 += e[c] * e[c];
    }
    const float w = (terms_at(d, i, xx, y) & kDyTerm) ? 1.f / (std::sqrt(n2) + reg) : 0.f;
    wy[xx] = w;
    for (int c = 0; c < 3; ++c) {
      fy[3 * xx + c] = w * e[c];
      by[3 * xx + c] = w * g[c];
    }
  }
}

}  // namespace

CgStart irls_reweight(const IrlsData& d, float reg, const float* x, const IrlsWeights& out,
                      float* r) {
  const int W = d.width, H = d.height;
  const float alpha = d.alpha, alpha2 = d.alpha * d.alpha;
  const auto s = parallel_rows_sum<9>(H, [&](int y0, int y1, std::array<double, 9>& sums) {
    RowBuffers& b = row_buffers(W);
    float *fy_above = b.fy_above.data(), *by_above = b.by_above.data();
    float *fy_row = b.fy_row.data(), *by_row = b.by_row.data();
    const float* wy_above = b.wy_above.data();
    if (y0 > 0) {
      vertical_edges(d, reg, x, y0 - 1, b.wy_above.data(), fy_above, by_above);
    } else {  // no row above the image: its terms are absent
      std::fill_n(fy_above, 3 * W, 0.f);
      std::fill_n(by_above, 3 * W, 0.f);
      std::fill_n(b.wy_above.data(), W, 0.f);
    }

    for (int y = y0; y < y1; ++y) {
      const size_t row = size_t(y) * W;
      vertical_edges(d, reg, x, y, out.wy + row, fy_row, by_row);

      // --- Left to right: the primal and x terms, the diagonal and the residual
      //   r = W0 e0 - fx + fx_left - fy + fy_above   (e = data - operator applied to x),
      // with the x-fluxes of the left neighbour carried along.
      float fx_left[3] = {0.f, 0.f, 0.f}, bx_left[3] = {0.f, 0.f, 0.f}, wx_left = 0.f;
      for (int xx = 0; xx < W; ++xx) {
        const size_t i = row + xx, ir = row + std::min(xx + 1, W - 1);
        const uint8_t t = terms_at(d, i, xx, y);
        const float* p0 = d.primal + 3 * i;
        const float* gx = d.gradient_x + 3 * i;
        float e0[3], ex[3], n0 = 0.f, nx = 0.f;
        for (int c = 0; c < 3; ++c) {
          e0[c] = p0[c] - x[3 * i + c];
          ex[c] = gx[c] - (x[3 * ir + c] - x[3 * i + c]);
          n0 += e0[c] * e0[c];
          nx += ex[c] * ex[c];
        }
        const float w0 = (t & kPrimalTerm) ? alpha2 / (alpha * std::sqrt(n0) + reg) : 0.f;
        const float wx = (t & kDxTerm) ? 1.f / (std::sqrt(nx) + reg) : 0.f;
        const float diag = w0 + wx + wx_left + out.wy[i] + wy_above[xx];
        const float inv = diag > 0.f ? 1.f / diag : 0.f;
        out.w0[i] = w0;
        out.wx[i] = wx;
        out.inv_diagonal[i] = inv;
        for (int c = 0; c < 3; ++c) {
          const float fx = wx * ex[c], bx = wx * gx[c];
          const float ri = w0 * e0[c] - fx + fx_left[c] - fy_row[3 * xx + c] + fy_above[3 * xx + c];
          const float bi = w0 * p0[c] - bx + bx_left[c] - by_row[3 * xx + c] + by_above[3 * xx + c];
          r[3 * i + c] = ri;
          sums[c] += double(ri) * ri;
          sums[3 + c] += double(bi) * bi;
          sums[6 + c] += double(ri) * inv * ri;
          fx_left[c] = fx;
          bx_left[c] = bx;
        }
        wx_left = wx;
      }
      std::swap(fy_above, fy_row);
      std::swap(by_above, by_row);
      wy_above = out.wy + row;
    }
  });
  CgStart start;
  for (int c = 0; c < 3; ++c) {
    start.rr[c] = s[c];
    start.bb[c] = s[3 + c];
    start.rz[c] = s[6 + c];
  }
  return start;
}

}  // namespace gdpt::detail
