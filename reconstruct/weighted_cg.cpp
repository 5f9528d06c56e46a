#include "reconstruct/weighted_cg.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/huge_pages.h"
#include "reconstruct/parallel.h"
#include "reconstruct/stencil_lanes.h"

namespace gdpt::detail {

void CgWorkspace::resize(size_t values) {
  if (r.size() == values) return;
  resize_huge(r, values);
  resize_huge(p, values);
  resize_huge(p_next, values);
  resize_huge(q, values);
}

namespace {

// Jacobi scale of pixel i, or 1 for plain CG.
template <bool kPreconditioned>
inline float precondition(const float* inv_diagonal, size_t i) {
  if constexpr (kPreconditioned)
    return inv_diagonal[i];
  else
    return 1.f;
}

// Residual r = b - A x and the right-hand side b, per channel, with sums[0..2] = |r_c|^2,
// sums[3..5] = |b_c|^2, sums[6..8] = <r_c, z_c> (z = D^-1 r). Written with the term residuals
//   e0 = primal - x,  ex = dx - Dx x,  ey = dy - Dy x:
//   r = W0 e0 + Dx^T (Wx ex) + Dy^T (Wy ey),  (Dx^T g)(x) = g(x - 1) - g(x).
template <bool kPreconditioned>
std::array<double, 9> residual_pass(const WeightedProblem& pb, const float* x, float* r) {
  const int W = pb.width, H = pb.height;
  return parallel_rows_sum<9>(H, [&](int y0, int y1, std::array<double, 9>& s) {
    for (int y = y0; y < y1; ++y) {
      // Clamped neighbours carry zero weight (Neumann); the clamp only keeps reads in bounds.
      const size_t row = size_t(y) * W, up = size_t(y > 0 ? y - 1 : y) * W;
      const size_t down = size_t(y < H - 1 ? y + 1 : y) * W;
      for (int xx = 0; xx < W; ++xx) {
        const size_t i = row + xx;
        const size_t ir = row + std::min(xx + 1, W - 1), il = row + std::max(xx - 1, 0);
        const size_t id = down + xx, iu = up + xx;
        const float w0 = pb.w0[i], wx = pb.wx[i], wy = pb.wy[i];
        const float wxl = xx > 0 ? pb.wx[il] : 0.f, wyu = y > 0 ? pb.wy[iu] : 0.f;
        const float d = precondition<kPreconditioned>(pb.inv_diagonal, i);
        for (int c = 0; c < 3; ++c) {
          const float xi = x[3 * i + c];
          const float p0 = pb.primal[3 * i + c];
          const float gx = pb.gradient_x[3 * i + c], gxl = pb.gradient_x[3 * il + c];
          const float gy = pb.gradient_y[3 * i + c], gyu = pb.gradient_y[3 * iu + c];
          const float ex = gx - (x[3 * ir + c] - xi), exl = gxl - (xi - x[3 * il + c]);
          const float ey = gy - (x[3 * id + c] - xi), eyu = gyu - (xi - x[3 * iu + c]);
          const float ri = w0 * (p0 - xi) - wx * ex + wxl * exl - wy * ey + wyu * eyu;
          const float bi = w0 * p0 - wx * gx + wxl * gxl - wy * gy + wyu * gyu;
          r[3 * i + c] = ri;
          s[c] += double(ri) * ri;
          s[3 + c] += double(bi) * bi;
          s[6 + c] += double(ri) * d * ri;
        }
      }
    }
  });
}

// Pixels are processed in groups of kGroup (stencil_lanes.h). Reductions keep one double
// accumulator per lane, folded into the channel sums in a fixed order (deterministic).

// Search direction v = z + beta p (z = D^-1 r) of the pixels [i0, i0 + W) of one row, into `v`.
// p == nullptr on the first step (beta = 0): p is not read, so it needs no clearing.
// With `zc` (the coarse row below this row), s P zc is added: the fused additive two-level
// preconditioner (CgPreconditioner::Coarse).
template <bool kPreconditioned>
inline void direction_row(const float* dg, const float* r, const float* p,
                          const std::array<float, 3>& beta, size_t i0, int W, float* v,
                          const float* zc = nullptr, float s = 0.f) {
  float b[kLanes];
  for (int k = 0; k < kLanes; ++k) b[k] = p ? beta[k % 3] : 0.f;
  const float* rr = r + 3 * i0;
  const float* pp = p ? p + 3 * i0 : rr;  // read but multiplied by 0 when there is no p
  int x = 0;
  for (; x + kGroup <= W; x += kGroup) {
    float d[kLanes];
    for (int k = 0; k < kLanes; ++k) d[k] = precondition<kPreconditioned>(dg, i0 + x + k / 3);
    for (int k = 0; k < kLanes; ++k) v[3 * x + k] = d[k] * rr[3 * x + k] + b[k] * pp[3 * x + k];
  }
  for (; x < W; ++x) {
    const float d = precondition<kPreconditioned>(dg, i0 + x);
    for (int c = 0; c < 3; ++c) v[3 * x + c] = d * rr[3 * x + c] + b[c] * pp[3 * x + c];
  }
  if (zc)
    for (x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) v[3 * x + c] += s * zc[3 * (x / 2) + c];
}

// Per-thread rows of v above and below a chunk: those rows belong to the neighbouring chunks,
// whose threads may be writing them, so each chunk forms its own copy.
struct HaloRows {
  std::vector<float> above, below;
  std::vector<float> no_weights;  // zeros: the weights above the first row
};

HaloRows& halo_rows(int W) {
  thread_local HaloRows rows;
  if (rows.above.size() < size_t(3) * W) {
    rows.above.resize(size_t(3) * W);
    rows.below.resize(size_t(3) * W);
    rows.no_weights.assign(size_t(W), 0.f);
  }
  return rows;
}

// Pass 1 of a CG step: p_next = z + beta p (z = D^-1 r; p == nullptr on the first step) and
// q = A p_next; returns <p_next, q>.
// A v = W0 v + Wx (v - v_right) + Wx_left (v - v_left) + Wy (v - v_down) + Wy_up (v - v_up).
// Each chunk first writes its rows of p_next (plus private copies of the rows just above and
// below it), then applies the stencil to them while they are still in cache: v is formed once
// per value, not once per stencil point.
template <bool kPreconditioned>
std::array<double, 3> direction_pass(const WeightedProblem& pb, const float* r, const float* p,
                                     const std::array<float, 3>& beta, float* p_next, float* q,
                                     const CgPreconditioner::Coarse* coarse = nullptr) {
  const int W = pb.width, H = pb.height;
  const float* dg = pb.inv_diagonal;
  auto row = [&](int y, float* out) {
    const float* zc = coarse ? coarse->z + 3 * size_t(y / 2) * coarse->width : nullptr;
    direction_row<kPreconditioned>(dg, r, p, beta, size_t(y) * W, W, out, zc,
                                   coarse ? coarse->scale : 0.f);
  };
  return parallel_rows_sum<3>(H, [&](int y0, int y1, std::array<double, 3>& s) {
    HaloRows& halo = halo_rows(W);
    // --- v for the chunk's rows and the two halo rows.
    for (int y = y0; y < y1; ++y) row(y, p_next + 3 * size_t(y) * W);
    if (y0 > 0) row(y0 - 1, halo.above.data());
    if (y1 < H) row(y1, halo.below.data());

    // --- q = A v row by row. A missing neighbour (image border) has zero weight; the row itself
    // stands in for it so that every read stays in bounds.
    double acc[kLanes] = {};
    for (int y = y0; y < y1; ++y) {
      const size_t row = size_t(y) * W;
      const float* vc = p_next + 3 * row;
      const float* vu = y == 0 ? vc : y == y0 ? halo.above.data() : vc - 3 * size_t(W);
      const float* vd = y == H - 1 ? vc : y == y1 - 1 ? halo.below.data() : vc + 3 * size_t(W);
      const float* w0 = pb.w0 + row;
      const float* wx = pb.wx + row;
      const float* wy = pb.wy + row;
      const float* wyu = y > 0 ? pb.wy + row - W : halo.no_weights.data();
      float* qr = q + 3 * row;
      auto pixel = [&](int x, int xl, int xr, float wxl) {
        const float a0 = w0[x], ax = wx[x], ay = wy[x], ayu = wyu[x];
        for (int c = 0; c < 3; ++c) {
          const float v = vc[3 * x + c];
          const float vr = vc[3 * xr + c], vl = vc[3 * xl + c];
          const float av = a0 * v + ax * (v - vr) + wxl * (v - vl) + ay * (v - vd[3 * x + c]) +
                           ayu * (v - vu[3 * x + c]);
          qr[3 * x + c] = av;
          acc[c] += double(v) * av;
        }
      };
      pixel(0, 0, std::min(1, W - 1), 0.f);
      int x = 1;
      for (; x + kGroup <= W - 1; x += kGroup) {  // interior pixels: both x-neighbours exist
        StencilLanes a;
        a.gather(w0, wx, wy, wyu, x);
        const float *vg = vc + 3 * x, *vdg = vd + 3 * x, *vug = vu + 3 * x;
        float* qg = qr + 3 * x;
        for (int k = 0; k < kLanes; ++k) {
          const float av = a.apply(k, vg, vdg, vug);
          qg[k] = av;
          acc[k] += double(vg[k]) * av;
        }
      }
      for (; x < W - 1; ++x) pixel(x, x - 1, x + 1, wx[x - 1]);
      if (W > 1) pixel(W - 1, W - 2, W - 1, wx[W - 2]);
    }
    for (int k = 0; k < kLanes; ++k) s[k % 3] += acc[k];
  });
}

// Pass 2 of a CG step: x += a p, r -= a q; returns |r_c|^2 (0..2) and <r_c, z_c> (3..5). With
// `coarse`, also rc = P^T r into coarse->r (the chunk's rows are still in cache).
template <bool kPreconditioned>
std::array<double, 6> update_pass(const WeightedProblem& pb, const std::array<float, 3>& a,
                                  const float* p, const float* q, float* x, float* r,
                                  const CgPreconditioner::Coarse* coarse = nullptr) {
  const int W = pb.width;
  float a_lane[kLanes];
  for (int k = 0; k < kLanes; ++k) a_lane[k] = a[k % 3];
  return parallel_rows_sum<6>(pb.height, [&](int y0, int y1, std::array<double, 6>& s) {
    const size_t begin = size_t(y0) * W, end = size_t(y1) * W;
    double rr[kLanes] = {}, rz[kLanes] = {};
    size_t i = begin;
    for (; i + kGroup <= end; i += kGroup) {
      float d[kLanes];
      for (int k = 0; k < kLanes; ++k)
        d[k] = precondition<kPreconditioned>(pb.inv_diagonal, i + k / 3);
      float* xg = x + 3 * i;
      float* rg = r + 3 * i;
      const float* pg = p + 3 * i;
      const float* qg = q + 3 * i;
      for (int k = 0; k < kLanes; ++k) {
        xg[k] += a_lane[k] * pg[k];
        const float ri = rg[k] - a_lane[k] * qg[k];
        rg[k] = ri;
        rr[k] += double(ri) * ri;
        rz[k] += double(ri) * d[k] * ri;
      }
    }
    for (; i < end; ++i) {  // the chunk's last pixels, lanes 0..2
      const float d = precondition<kPreconditioned>(pb.inv_diagonal, i);
      for (int c = 0; c < 3; ++c) {
        x[3 * i + c] += a[c] * p[3 * i + c];
        const float ri = r[3 * i + c] - a[c] * q[3 * i + c];
        r[3 * i + c] = ri;
        rr[c] += double(ri) * ri;
        rz[c] += double(ri) * d * ri;
      }
    }
    for (int k = 0; k < kLanes; ++k) {
      s[k % 3] += rr[k];
      s[3 + k % 3] += rz[k];
    }
    if (coarse)
      for (int y = y0; y < y1; ++y)
        restrict_row(W, y, r + 3 * size_t(y) * W, nullptr, coarse->r, coarse->width);
  });
}

// rc = P^T r alone (the start of a fused two-level solve).
void restrict_pass(const WeightedProblem& pb, const float* r, const CgPreconditioner::Coarse& c) {
  parallel_rows(pb.height, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      restrict_row(pb.width, y, r + 3 * size_t(y) * pb.width, nullptr, c.r, c.width);
  });
}

// One CG step's two passes: with the Jacobi scaling formed on the fly (kPreconditioned; plus the
// fused coarse term with `coarse`), with none, or with `pc`, z = M^-1 r read from ws.z. Returns
// <p, q> (0..2), |r_c|^2 (3..5) and the Jacobi <r_c, z_c> (6..8). `restrict_to`: the update
// pass's P^T r target (the fused form, unless this is the last step).
template <bool kPreconditioned, class StepSizes>
std::array<double, 9> cg_step(const WeightedProblem& pb, const CgPreconditioner* pc,
                              const CgPreconditioner::Coarse* coarse,
                              const CgPreconditioner::Coarse* restrict_to, bool first,
                              const std::array<float, 3>& beta, const StepSizes& step_sizes,
                              float* x, CgWorkspace& ws) {
  const float* p = first ? nullptr : ws.p.data();
  const auto pq =
      pc ? direction_pass<false>(pb, ws.z.data(), p, beta, ws.p_next.data(), ws.q.data())
         : direction_pass<kPreconditioned>(pb, ws.r.data(), p, beta, ws.p_next.data(), ws.q.data(),
                                           coarse);
  ws.p.swap(ws.p_next);
  const std::array<float, 3> a = step_sizes(pq);
  const auto u = pc ? update_pass<false>(pb, a, ws.p.data(), ws.q.data(), x, ws.r.data())
                    : update_pass<kPreconditioned>(pb, a, ws.p.data(), ws.q.data(), x, ws.r.data(),
                                                   restrict_to);
  return {pq[0], pq[1], pq[2], u[0], u[1], u[2], u[3], u[4], u[5]};
}

// <r_c, z_c> of the fused two-level form: the Jacobi part plus scale <rc_c, zc_c>.
std::array<double, 3> fused_rz(const std::array<double, 3>& jacobi, CgPreconditioner& pc,
                               const CgPreconditioner::Coarse& coarse) {
  const auto c = pc.solve_coarse();
  std::array<double, 3> rz{};
  for (int k = 0; k < 3; ++k) rz[k] = jacobi[k] + double(coarse.scale) * c[k];
  return rz;
}

template <bool kPreconditioned>
CgResult run_cg(const WeightedProblem& pb, float* x, const CgStart& start, int max_iterations,
                double tolerance, CgWorkspace& ws) {
  // A preconditioner's two-level form is fused into the Jacobi passes; other forms are applied.
  CgPreconditioner* const given = pb.preconditioner;
  const CgPreconditioner::Coarse* coarse = given && kPreconditioned ? given->coarse() : nullptr;
  CgPreconditioner* const pc = coarse ? nullptr : given;
  std::array<double, 3> rr = start.rr, rz = start.rz;
  const double bb_max = std::max({start.bb[0], start.bb[1], start.bb[2]});
  // A channel whose b is zero (a black channel) is measured against the brightest channel.
  std::array<double, 3> denom{};
  for (int c = 0; c < 3; ++c) denom[c] = std::max(start.bb[c], 1e-12 * bb_max);

  CgResult result;
  auto relative = [&] {
    double worst = 0.0;
    for (int c = 0; c < 3; ++c)
      if (denom[c] > 0) worst = std::max(worst, std::sqrt(rr[c] / denom[c]));
    return worst;
  };
  if (bb_max == 0.0 && rr[0] + rr[1] + rr[2] == 0.0) return result;  // x = 0 solves b = 0
  if (max_iterations > 0 && coarse) {
    restrict_pass(pb, ws.r.data(), *coarse);
    rz = fused_rz(start.rz, *given, *coarse);
  } else if (max_iterations > 0 && pc) {
    if (ws.z.size() != ws.r.size()) resize_huge(ws.z, ws.r.size());
    rz = pc->apply(ws.r.data(), ws.z.data());
  }

  std::array<double, 3> rz_prev = rz;
  for (int it = 0; it < max_iterations; ++it) {
    std::array<bool, 3> active{};
    bool any = false;
    for (int c = 0; c < 3; ++c) {
      active[c] = rr[c] > tolerance * tolerance * denom[c] && rz[c] > 0;
      any = any || active[c];
    }
    if (!any) break;

    std::array<float, 3> beta{};
    if (it > 0)
      for (int c = 0; c < 3; ++c)
        beta[c] = active[c] && rz_prev[c] > 0 ? float(rz[c] / rz_prev[c]) : 0.f;
    auto step_sizes = [&](const std::array<double, 3>& pq) {
      std::array<float, 3> a{};
      for (int c = 0; c < 3; ++c) a[c] = active[c] && pq[c] > 0 ? float(rz[c] / pq[c]) : 0.f;
      return a;
    };
    // The preconditioned residual is needed for a next step only.
    const bool last = it + 1 == max_iterations;
    const auto s = cg_step<kPreconditioned>(pb, pc, coarse, last ? nullptr : coarse, it == 0, beta,
                                            step_sizes, x, ws);
    rz_prev = rz;
    std::array<double, 3> rz_next{s[6], s[7], s[8]};
    if (coarse && !last)
      rz_next = fused_rz(rz_next, *given, *coarse);
    else if (pc && !last)
      rz_next = pc->apply(ws.r.data(), ws.z.data());
    for (int c = 0; c < 3; ++c)
      if (active[c]) {
        rr[c] = s[3 + c];
        rz[c] = rz_next[c];
      }
    ++result.iterations;
  }
  result.relative_residual = relative();
  return result;
}

}  // namespace

void restrict_row(int width, int y, const float* v, const float* a, float* rc, int coarse_width) {
  float* cr = rc + 3 * size_t(y / 2) * coarse_width;
  if (y % 2 == 0) std::fill_n(cr, 3 * size_t(coarse_width), 0.f);
  const int pairs = width / 2;
  if (a)
    for (int i = 0; i < 3 * pairs; ++i) {
      const int k = 2 * i - i % 3;  // channel i % 3 of the pair's first pixel
      cr[i] += (v[k] - a[k]) + (v[k + 3] - a[k + 3]);
    }
  else
    for (int i = 0; i < 3 * pairs; ++i) {
      const int k = 2 * i - i % 3;
      cr[i] += v[k] + v[k + 3];
    }
  if (width % 2)  // a last block of one column
    for (int c = 0; c < 3; ++c)
      cr[3 * pairs + c] += v[3 * (width - 1) + c] - (a ? a[3 * (width - 1) + c] : 0.f);
}

std::vector<float> jacobi_inverse_diagonal(const WeightedProblem& pb) {
  const int W = pb.width, H = pb.height;
  auto d = huge_vector<float>(size_t(W) * H);
  parallel_rows(H, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        const float diag = pb.w0[i] + pb.wx[i] + (x > 0 ? pb.wx[i - 1] : 0.f) + pb.wy[i] +
                           (y > 0 ? pb.wy[i - W] : 0.f);
        d[i] = diag > 0.f ? 1.f / diag : 0.f;
      }
  });
  return d;
}

double weighted_relative_residual(const WeightedProblem& problem, const float* x) {
  std::vector<float> r(size_t(problem.width) * problem.height * 3);
  const auto s = residual_pass<false>(problem, x, r.data());
  double worst = 0.0;
  for (int c = 0; c < 3; ++c)
    if (s[3 + c] > 0) worst = std::max(worst, std::sqrt(s[c] / s[3 + c]));
  return worst;
}

CgResult solve_weighted_cg(const WeightedProblem& pb, float* x, int max_iterations,
                           double tolerance, CgWorkspace& ws) {
  ws.resize(size_t(pb.width) * pb.height * 3);
  const auto s = pb.inv_diagonal ? residual_pass<true>(pb, x, ws.r.data())
                                 : residual_pass<false>(pb, x, ws.r.data());
  CgStart start;
  for (int c = 0; c < 3; ++c) {
    start.rr[c] = s[c];
    start.bb[c] = s[3 + c];
    start.rz[c] = s[6 + c];
  }
  return solve_weighted_cg_from_residual(pb, x, start, max_iterations, tolerance, ws);
}

CgResult solve_weighted_cg_from_residual(const WeightedProblem& pb, float* x, const CgStart& start,
                                         int max_iterations, double tolerance, CgWorkspace& ws) {
  ws.resize(size_t(pb.width) * pb.height * 3);
  return pb.inv_diagonal ? run_cg<true>(pb, x, start, max_iterations, tolerance, ws)
                         : run_cg<false>(pb, x, start, max_iterations, tolerance, ws);
}

}  // namespace gdpt::detail
