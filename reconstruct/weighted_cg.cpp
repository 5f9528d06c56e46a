#include "reconstruct/weighted_cg.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

void CgWorkspace::resize(size_t values) {
  r.resize(values);
  p.resize(values);
  p_next.resize(values);
  q.resize(values);
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

// Pass 1 of a CG step: p_next = z + beta p (z = D^-1 r) and q = A p_next; returns <p_next, q>.
// A v = W0 v + Wx (v - v_right) + Wx_left (v - v_left) + Wy (v - v_down) + Wy_up (v - v_up).
template <bool kPreconditioned>
std::array<double, 3> direction_pass(const WeightedProblem& pb, const float* r, const float* p,
                                     const std::array<float, 3>& beta, float* p_next, float* q) {
  const int W = pb.width, H = pb.height;
  const float* dg = pb.inv_diagonal;
  return parallel_rows_sum<3>(H, [&](int y0, int y1, std::array<double, 3>& s) {
    for (int y = y0; y < y1; ++y) {
      const size_t row = size_t(y) * W;
      const size_t up = size_t(y > 0 ? y - 1 : y) * W, down = size_t(y < H - 1 ? y + 1 : y) * W;
      for (int xx = 0; xx < W; ++xx) {
        const size_t i = row + xx;
        const size_t ir = row + std::min(xx + 1, W - 1), il = row + std::max(xx - 1, 0);
        const size_t id = down + xx, iu = up + xx;
        const float w0 = pb.w0[i], wx = pb.wx[i], wy = pb.wy[i];
        const float wxl = xx > 0 ? pb.wx[il] : 0.f, wyu = y > 0 ? pb.wy[iu] : 0.f;
        const float d = precondition<kPreconditioned>(dg, i);
        const float dr = precondition<kPreconditioned>(dg, ir);
        const float dl = precondition<kPreconditioned>(dg, il);
        const float dd = precondition<kPreconditioned>(dg, id);
        const float du = precondition<kPreconditioned>(dg, iu);
        for (int c = 0; c < 3; ++c) {
          const float b = beta[c];
          const float v = d * r[3 * i + c] + b * p[3 * i + c];
          const float vr = dr * r[3 * ir + c] + b * p[3 * ir + c];
          const float vl = dl * r[3 * il + c] + b * p[3 * il + c];
          const float vd = dd * r[3 * id + c] + b * p[3 * id + c];
          const float vu = du * r[3 * iu + c] + b * p[3 * iu + c];
          const float av = w0 * v + wx * (v - vr) + wxl * (v - vl) + wy * (v - vd) + wyu * (v - vu);
          p_next[3 * i + c] = v;
          q[3 * i + c] = av;
          s[c] += double(v) * av;
        }
      }
    }
  });
}

// Pass 2 of a CG step: x += a p, r -= a q; returns |r_c|^2 (0..2) and <r_c, z_c> (3..5).
template <bool kPreconditioned>
std::array<double, 6> update_pass(const WeightedProblem& pb, const std::array<float, 3>& a,
                                  const float* p, const float* q, float* x, float* r) {
  const int W = pb.width;
  return parallel_rows_sum<6>(pb.height, [&](int y0, int y1, std::array<double, 6>& s) {
    const size_t begin = size_t(y0) * W, end = size_t(y1) * W;
    for (size_t i = begin; i < end; ++i) {
      const float d = precondition<kPreconditioned>(pb.inv_diagonal, i);
      for (int c = 0; c < 3; ++c) {
        x[3 * i + c] += a[c] * p[3 * i + c];
        const float ri = r[3 * i + c] - a[c] * q[3 * i + c];
        r[3 * i + c] = ri;
        s[c] += double(ri) * ri;
        s[3 + c] += double(ri) * d * ri;
      }
    }
  });
}

template <bool kPreconditioned>
CgResult run_cg(const WeightedProblem& pb, float* x, int max_iterations, double tolerance,
                CgWorkspace& ws) {
  const size_t n = size_t(pb.width) * pb.height * 3;
  ws.resize(n);
  std::fill(ws.p.begin(), ws.p.end(), 0.f);  // beta = 0 on the first step must not meet garbage

  const auto s = residual_pass<kPreconditioned>(pb, x, ws.r.data());
  std::array<double, 3> rr = {s[0], s[1], s[2]}, rz = {s[6], s[7], s[8]};
  const double bb_max = std::max({s[3], s[4], s[5]});
  // A channel whose b is zero (a black channel) is measured against the brightest channel.
  std::array<double, 3> denom{};
  for (int c = 0; c < 3; ++c) denom[c] = std::max(s[3 + c], 1e-12 * bb_max);

  CgResult result;
  auto relative = [&] {
    double worst = 0.0;
    for (int c = 0; c < 3; ++c)
      if (denom[c] > 0) worst = std::max(worst, std::sqrt(rr[c] / denom[c]));
    return worst;
  };
  if (bb_max == 0.0 && rr[0] + rr[1] + rr[2] == 0.0) return result;  // x = 0 solves b = 0

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
    const auto pq = direction_pass<kPreconditioned>(pb, ws.r.data(), ws.p.data(), beta,
                                                    ws.p_next.data(), ws.q.data());
    ws.p.swap(ws.p_next);

    std::array<float, 3> a{};
    for (int c = 0; c < 3; ++c) a[c] = active[c] && pq[c] > 0 ? float(rz[c] / pq[c]) : 0.f;
    rz_prev = rz;
    const auto u = update_pass<kPreconditioned>(pb, a, ws.p.data(), ws.q.data(), x, ws.r.data());
    for (int c = 0; c < 3; ++c)
      if (active[c]) {
        rr[c] = u[c];
        rz[c] = u[3 + c];
      }
    ++result.iterations;
  }
  result.relative_residual = relative();
  return result;
}

}  // namespace

std::vector<float> jacobi_inverse_diagonal(const WeightedProblem& pb) {
  const int W = pb.width, H = pb.height;
  std::vector<float> d(size_t(W) * H);
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
  return pb.inv_diagonal ? run_cg<true>(pb, x, max_iterations, tolerance, ws)
                         : run_cg<false>(pb, x, max_iterations, tolerance, ws);
}

}  // namespace gdpt::detail
