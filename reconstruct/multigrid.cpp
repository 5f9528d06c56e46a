#include "reconstruct/multigrid.h"

#include <algorithm>
#include <utility>

#include "reconstruct/parallel.h"
#include "reconstruct/stencil_lanes.h"

namespace gdpt::detail {

namespace {

using Grid = MultigridGrid;

// Per-thread rows of a stencil pass: u above, at and below the current row, and A u of it.
struct Rows {
  std::vector<float> u[3], au;
  std::vector<float> zeros;  // the weights above the first row
};

Rows& rows_for(int width) {
  thread_local Rows rows;
  if (rows.au.size() < size_t(3) * width) {
    for (auto& v : rows.u) v.resize(size_t(3) * width);
    rows.au.resize(size_t(3) * width);
    rows.zeros.assign(size_t(width), 0.f);
  }
  return rows;
}

// u = omega D^-1 r + s (P zc) on row y, RGB; zc == nullptr: no coarse term (wc: coarse width).
void smooth_row(const Grid& g, const float* r, float omega, const float* zc, int wc, float s, int y,
                float* u) {
  const size_t row = size_t(y) * g.width;
  const float* rr = r + 3 * row;
  const float* inv = g.inv + row;
  const int W = g.width;
  int x = 0;
  for (; x + kGroup <= W; x += kGroup) {
    float d[kLanes];
    for (int k = 0; k < kLanes; ++k) d[k] = omega * inv[x + k / 3];
    for (int k = 0; k < kLanes; ++k) u[3 * x + k] = d[k] * rr[3 * x + k];
  }
  for (; x < W; ++x) {
    const float d = omega * inv[x];
    for (int c = 0; c < 3; ++c) u[3 * x + c] = d * rr[3 * x + c];
  }
  if (!zc) return;
  const float* zr = zc + 3 * size_t(y / 2) * wc;
  x = 0;
  for (; x + kGroup <= W; x += kGroup) {  // pixels x, x + 1 in block x / 2, x + 2, x + 3 next
    const float* zb = zr + 3 * (x / 2);
    for (int k = 0; k < kLanes; ++k) u[3 * x + k] += s * zb[k % 3 + 3 * (k / 6)];
  }
  for (; x < W; ++x)
    for (int c = 0; c < 3; ++c) u[3 * x + c] += s * zr[3 * (x / 2) + c];
}

// au = A u on row y from u's rows above (uu), at (uc) and below (ud). A neighbour outside the
// image has zero weight, so any row may stand in for a missing one; `zeros`: W zero weights.
void apply_row(const Grid& g, int y, const float* uu, const float* uc, const float* ud,
               const float* zeros, float* au) {
  const int W = g.width;
  const size_t row = size_t(y) * W;
  const float *w0 = g.w0 + row, *wx = g.wx + row, *wy = g.wy + row;
  const float* wyu = y > 0 ? g.wy + row - W : zeros;
  auto border = [&](int x) {
    const int xl = std::max(x - 1, 0), xr = std::min(x + 1, W - 1);
    const float wxl = x > 0 ? wx[x - 1] : 0.f;
    for (int c = 0; c < 3; ++c) {
      const float v = uc[3 * x + c];
      au[3 * x + c] = w0[x] * v + wx[x] * (v - uc[3 * xr + c]) + wxl * (v - uc[3 * xl + c]) +
                      wy[x] * (v - ud[3 * x + c]) + wyu[x] * (v - uu[3 * x + c]);
    }
  };
  border(0);
  int x = 1;
  // Interior in groups of kGroup pixels, lane k = channel k % 3 of pixel k / 3: vectorises.
  for (; x + kGroup <= W - 1; x += kGroup) {
    StencilLanes a;
    a.gather(w0, wx, wy, wyu, x);
    const float *v = uc + 3 * x, *vd = ud + 3 * x, *vu = uu + 3 * x;
    float* out = au + 3 * x;
    for (int k = 0; k < kLanes; ++k) out[k] = a.apply(k, v, vd, vu);
  }
  for (; x < W - 1; ++x) {
    const float a0 = w0[x], ax = wx[x], axl = wx[x - 1], ay = wy[x], ayu = wyu[x];
    const float* v = uc + 3 * x;
    for (int c = 0; c < 3; ++c) {
      const float vc = v[c];
      au[3 * x + c] = a0 * vc + ax * (vc - v[c + 3]) + axl * (vc - v[c - 3]) +
                      ay * (vc - ud[3 * x + c]) + ayu * (vc - uu[3 * x + c]);
    }
  }
  if (W > 1) border(W - 1);
}

// For each row y of the chunk [y0, y1): u's rows around y made by make(y, row), A u of row y, then
// body(y, u of row y, A u of row y). The chunk forms its own copies of the rows next to it.
template <class Make, class Body>
void stencil_rows(const Grid& g, int y0, int y1, const Make& make, const Body& body) {
  Rows& rows = rows_for(g.width);
  float* up = rows.u[0].data();
  float* cur = rows.u[1].data();
  float* down = rows.u[2].data();
  if (y0 > 0) make(y0 - 1, up);
  make(y0, cur);
  for (int y = y0; y < y1; ++y) {
    const bool has_down = y + 1 < g.height;
    if (has_down) make(y + 1, down);
    apply_row(g, y, y > 0 ? up : cur, cur, has_down ? down : cur, rows.zeros.data(),
              rows.au.data());
    body(y, cur, rows.au.data());
    std::swap(up, cur);  // up <- this row, cur <- the row below
    std::swap(cur, down);
  }
}

// rc = P^T r.
void restrict_residual(const Grid& g, const float* r, float* rc, int wc) {
  parallel_rows(g.height, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      restrict_row(g.width, y, r + 3 * size_t(y) * g.width, nullptr, rc, wc);
  });
}

// Pre-smoothing from z = 0 (z = omega D^-1 r) and rc = P^T (r - A z); z itself is formed again
// by the post-smoothing, so it is not stored.
void presmooth_restrict(const Grid& g, const float* r, float omega, float* rc, int wc) {
  parallel_rows(g.height, [&](int y0, int y1) {
    stencil_rows(
        g, y0, y1, [&](int y, float* u) { smooth_row(g, r, omega, nullptr, 0, 0.f, y, u); },
        [&](int y, const float*, const float* au) {
          restrict_row(g.width, y, r + 3 * size_t(y) * g.width, au, rc, wc);
        });
  });
}

// Row y of the post-smoothing z = u + omega D^-1 (r - A u), with <r, z> into acc (lane k:
// channel k % 3).
void postsmooth_row(const Grid& g, const float* r, float omega, int y, const float* u,
                    const float* au, float* z, double* acc) {
  const size_t row = size_t(y) * g.width;
  const float* rr = r + 3 * row;
  const float* inv = g.inv + row;
  float* zr = z + 3 * row;
  const int W = g.width;
  int x = 0;
  for (; x + kGroup <= W; x += kGroup) {
    float d[kLanes];
    for (int k = 0; k < kLanes; ++k) d[k] = omega * inv[x + k / 3];
    for (int k = 0; k < kLanes; ++k) {
      const int i = 3 * x + k;
      const float zi = u[i] + d[k] * (rr[i] - au[i]);
      zr[i] = zi;
      acc[k] += double(rr[i]) * zi;
    }
  }
  for (; x < W; ++x) {
    const float d = omega * inv[x];
    for (int c = 0; c < 3; ++c) {
      const int i = 3 * x + c;
      const float zi = u[i] + d * (rr[i] - au[i]);
      zr[i] = zi;
      acc[c] += double(rr[i]) * zi;
    }
  }
}

// Coarse correction and post-smoothing: u = omega D^-1 r + s P zc, z = u + omega D^-1 (r - A u);
// returns <r_c, z_c>.
std::array<double, 3> postsmooth(const Grid& g, const float* r, float omega, const float* zc,
                                 int wc, float s, float* z) {
  return parallel_rows_sum<3>(g.height, [&](int y0, int y1, std::array<double, 3>& sums) {
    double acc[kLanes] = {};
    stencil_rows(
        g, y0, y1, [&](int y, float* u) { smooth_row(g, r, omega, zc, wc, s, y, u); },
        [&](int y, const float* u, const float* au) {
          postsmooth_row(g, r, omega, y, u, au, z, acc);
        });
    for (int k = 0; k < kLanes; ++k) sums[k % 3] += acc[k];
  });
}

// The additive finest level: z = D^-1 r + s P zc (zc == nullptr: Jacobi); returns <r_c, z_c>.
std::array<double, 3> additive_combine(const Grid& g, const float* r, const float* zc, int wc,
                                       float s, float* z) {
  return parallel_rows_sum<3>(g.height, [&](int y0, int y1, std::array<double, 3>& sums) {
    double acc[3] = {};
    for (int y = y0; y < y1; ++y) {
      const size_t row = size_t(y) * g.width;
      const float* rr = r + 3 * row;
      const float* zr = zc ? zc + 3 * size_t(y / 2) * wc : nullptr;
      float* out = z + 3 * row;
      for (int x = 0; x < g.width; ++x)
        for (int c = 0; c < 3; ++c) {
          const float v = g.inv[row + x] * rr[3 * x + c] + (zr ? s * zr[3 * (x / 2) + c] : 0.f);
          out[3 * x + c] = v;
          acc[c] += double(rr[3 * x + c]) * v;
        }
    }
    for (int c = 0; c < 3; ++c) sums[c] += acc[c];
  });
}

// z = `sweeps` symmetric Gauss-Seidel sweeps (forward, then backward) from 0 on A z = r; serial:
// the coarsest level has a few dozen pixels. Returns <r_c, z_c>.
std::array<double, 3> coarsest_solve(const Grid& g, const float* r, int sweeps, float* z) {
  const int W = g.width, H = g.height;
  std::fill_n(z, 3 * size_t(W) * H, 0.f);
  auto relax = [&](int x, int y) {
    const size_t i = size_t(y) * W + x;
    float s[3] = {r[3 * i], r[3 * i + 1], r[3 * i + 2]};
    auto add = [&](size_t j, float w) {
      for (int c = 0; c < 3; ++c) s[c] += w * z[3 * j + c];
    };
    if (x + 1 < W) add(i + 1, g.wx[i]);
    if (x > 0) add(i - 1, g.wx[i - 1]);
    if (y + 1 < H) add(i + W, g.wy[i]);
    if (y > 0) add(i - W, g.wy[i - W]);
    for (int c = 0; c < 3; ++c) z[3 * i + c] = g.inv[i] * s[c];
  };
  for (int k = 0; k < sweeps; ++k) {
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) relax(x, y);
    for (int y = H - 1; y >= 0; --y)
      for (int x = W - 1; x >= 0; --x) relax(x, y);
  }
  std::array<double, 3> rz{};
  for (size_t i = 0; i < 3 * size_t(W) * H; ++i) rz[i % 3] += double(r[i]) * z[i];
  return rz;
}

// inv = 1 / diag(A) of a level (0 where the row is empty).
void invert_diagonal(int W, int H, const float* w0, const float* wx, const float* wy, float* inv) {
  parallel_rows(H, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        const float d =
            w0[i] + wx[i] + (x > 0 ? wx[i - 1] : 0.f) + wy[i] + (y > 0 ? wy[i - W] : 0.f);
        inv[i] = d > 0.f ? 1.f / d : 0.f;
      }
  });
}

}  // namespace

void coarsen_weights(int W, int H, const float* w0, const float* wx, const float* wy,
                     float edge_scale, float* coarse_w0, float* coarse_wx, float* coarse_wy) {
  const int wc = (W + 1) / 2, hc = (H + 1) / 2;
  parallel_rows(hc, [&](int y0, int y1) {
    for (int Y = y0; Y < y1; ++Y) {
      const bool has_y = 2 * Y + 1 < H;  // the block has a second row
      const size_t top = size_t(2 * Y) * W, bottom = top + W;
      for (int X = 0; X < wc; ++X) {
        const bool has_x = 2 * X + 1 < W;  // the block has a second column
        const size_t a = top + 2 * X, b = bottom + 2 * X;
        // Crossing x edges leave the block's second column, crossing y edges its second row.
        float s0 = w0[a], sx = 0.f, sy = 0.f;
        if (has_x) {
          s0 += w0[a + 1];
          sx += wx[a + 1];
        }
        if (has_y) {
          s0 += w0[b];
          sy += wy[b];
        }
        if (has_x && has_y) {
          s0 += w0[b + 1];
          sx += wx[b + 1];
          sy += wy[b + 1];
        }
        const size_t i = size_t(Y) * wc + X;
        coarse_w0[i] = s0;
        coarse_wx[i] = edge_scale * sx;
        coarse_wy[i] = edge_scale * sy;
      }
    }
  });
}

void WeightedMultigrid::build(const WeightedProblem& pb) {
  const float* inv = pb.inv_diagonal;
  if (!inv) {
    fine_inv_ = jacobi_inverse_diagonal(pb);
    inv = fine_inv_.data();
  }
  fine_ = Grid{pb.width, pb.height, pb.w0, pb.wx, pb.wy, inv};
  Grid finer = fine_;
  size_t n = 0;
  const size_t smallest = size_t(std::max(1, options_.coarsest_pixels));
  while (size_t(finer.width) * finer.height > smallest) {
    if (coarse_.size() <= n) coarse_.emplace_back();  // moves keep the buffers `finer` points to
    Level& l = coarse_[n++];
    l.width = (finer.width + 1) / 2;
    l.height = (finer.height + 1) / 2;
    const size_t px = size_t(l.width) * l.height;
    for (auto* v : {&l.w0, &l.wx, &l.wy, &l.inv}) v->resize(px);
    l.r.resize(3 * px);
    l.z.resize(3 * px);
    coarsen_weights(finer.width, finer.height, finer.w0, finer.wx, finer.wy, options_.edge_scale,
                    l.w0.data(), l.wx.data(), l.wy.data());
    invert_diagonal(l.width, l.height, l.w0.data(), l.wx.data(), l.wy.data(), l.inv.data());
    finer = l.grid();
  }
  coarse_.resize(n);
  // CG fuses the additive form into its Jacobi passes when the problem has the diagonal.
  fused_ = options_.form == MultigridOptions::kAdditive && pb.inv_diagonal && n > 0;
  if (fused_)
    fused_view_ = {coarse_[0].r.data(), coarse_[0].z.data(), coarse_[0].width,
                   options_.coarse_scale};
}

std::array<double, 3> WeightedMultigrid::cycle(size_t k) {
  Level& l = coarse_[k];
  const Grid g = l.grid();
  if (k + 1 == coarse_.size())
    return coarsest_solve(g, l.r.data(), options_.coarsest_sweeps, l.z.data());
  Level& c = coarse_[k + 1];
  presmooth_restrict(g, l.r.data(), options_.omega, c.r.data(), c.width);
  cycle(k + 1);
  return postsmooth(g, l.r.data(), options_.omega, c.z.data(), c.width, options_.coarse_scale,
                    l.z.data());
}

std::array<double, 3> WeightedMultigrid::apply(const float* r, float* z) {
  const float s = options_.coarse_scale;
  if (coarse_.empty()) return additive_combine(fine_, r, nullptr, 0, 0.f, z);  // tiny image
  Level& c = coarse_.front();
  if (options_.form == MultigridOptions::kAdditive) {
    restrict_residual(fine_, r, c.r.data(), c.width);
    cycle(0);
    return additive_combine(fine_, r, c.z.data(), c.width, s, z);
  }
  presmooth_restrict(fine_, r, options_.omega, c.r.data(), c.width);
  cycle(0);
  return postsmooth(fine_, r, options_.omega, c.z.data(), c.width, s, z);
}

const CgPreconditioner::Coarse* WeightedMultigrid::coarse() const {
  return fused_ ? &fused_view_ : nullptr;
}

std::array<double, 3> WeightedMultigrid::solve_coarse() {
  return cycle(0);
}

}  // namespace gdpt::detail
