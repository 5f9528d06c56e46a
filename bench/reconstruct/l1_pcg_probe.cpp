#include "bench/reconstruct/l1_pcg_probe.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>

#include "reconstruct/dct_solver.h"
#include "reconstruct/irls_reweight.h"
#include "reconstruct/multigrid.h"
#include "reconstruct/parallel.h"
#include "reconstruct/reconstruct.h"
#include "reconstruct/weighted_cg.h"

namespace gdpt::bench {

namespace {

using detail::parallel_rows;
using detail::parallel_rows_sum;
using Vec = std::vector<float>;
using Preconditioner = std::function<void(const Vec& r, Vec& z)>;

// out = A v for the weighted problem (A v = W0 v + Dx^T Wx Dx v + Dy^T Wy Dy v, Neumann).
void apply(const detail::WeightedProblem& pb, const Vec& v, Vec& out) {
  const int W = pb.width, H = pb.height;
  parallel_rows(H, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        const float wl = x > 0 ? pb.wx[i - 1] : 0.f, wu = y > 0 ? pb.wy[i - W] : 0.f;
        for (int c = 0; c < 3; ++c) {
          const float vi = v[3 * i + c];
          float a = pb.w0[i] * vi;
          if (x < W - 1) a += pb.wx[i] * (vi - v[3 * (i + 1) + c]);
          if (x > 0) a += wl * (vi - v[3 * (i - 1) + c]);
          if (y < H - 1) a += pb.wy[i] * (vi - v[3 * (i + W) + c]);
          if (y > 0) a += wu * (vi - v[3 * (i - W) + c]);
          out[3 * i + c] = a;
        }
      }
  });
}

// b = W0 primal + Dx^T Wx dx + Dy^T Wy dy.
void rhs(const detail::WeightedProblem& pb, Vec& b) {
  const int W = pb.width, H = pb.height;
  parallel_rows(H, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        for (int c = 0; c < 3; ++c) {
          float v = pb.w0[i] * pb.primal[3 * i + c] - pb.wx[i] * pb.gradient_x[3 * i + c] -
                    pb.wy[i] * pb.gradient_y[3 * i + c];
          if (x > 0) v += pb.wx[i - 1] * pb.gradient_x[3 * (i - 1) + c];
          if (y > 0) v += pb.wy[i - W] * pb.gradient_y[3 * (i - W) + c];
          b[3 * i + c] = v;
        }
      }
  });
}

// Per-channel <a, b>.
std::array<double, 3> dot(int H, int W, const Vec& a, const Vec& b) {
  return parallel_rows_sum<3>(H, [&](int y0, int y1, std::array<double, 3>& s) {
    for (size_t i = 3 * size_t(y0) * W; i < 3 * size_t(y1) * W; ++i)
      s[i % 3] += double(a[i]) * b[i];
  });
}

struct PcgRun {
  int to_first = -1, to_second = -1;  // steps to the two targets (-1: not reached)
  double seconds_to_second = 0.0;
};

// Per-channel PCG from x until every channel's |r_c| / |b_c| has been below both targets (the
// steps to each recorded), or max_steps.
PcgRun run_pcg(const detail::WeightedProblem& pb, Vec x, const Preconditioner& precondition,
               double target_first, double target_second, int max_steps) {
  const auto t0 = std::chrono::steady_clock::now();
  const int W = pb.width, H = pb.height;
  const size_t n = size_t(W) * H * 3;
  Vec b(n), r(n), z(n), p(n), q(n);
  rhs(pb, b);
  apply(pb, x, q);
  for (size_t i = 0; i < n; ++i) r[i] = b[i] - q[i];
  const auto bb = dot(H, W, b, b);
  auto relative = [&] {
    const auto rr = dot(H, W, r, r);
    double worst = 0;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::sqrt(rr[c] / bb[c]));
    return worst;
  };
  PcgRun run;
  precondition(r, z);
  p = z;
  auto rz = dot(H, W, r, z);
  for (int step = 1; step <= max_steps; ++step) {
    apply(pb, p, q);
    const auto pq = dot(H, W, p, q);
    std::array<float, 3> a{};
    for (int c = 0; c < 3; ++c) a[c] = pq[c] > 0 ? float(rz[c] / pq[c]) : 0.f;
    for (size_t i = 0; i < n; ++i) {
      x[i] += a[i % 3] * p[i];
      r[i] -= a[i % 3] * q[i];
    }
    const double rel = relative();
    if (run.to_first < 0 && rel <= target_first) run.to_first = step;
    if (run.to_second < 0 && rel <= target_second) {
      run.to_second = step;
      run.seconds_to_second =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    if (run.to_first >= 0 && run.to_second >= 0) break;
    precondition(r, z);
    const auto rz_next = dot(H, W, r, z);
    std::array<float, 3> beta{};
    for (int c = 0; c < 3; ++c) beta[c] = rz[c] > 0 ? float(rz_next[c] / rz[c]) : 0.f;
    rz = rz_next;
    for (size_t i = 0; i < n; ++i) p[i] = z[i] + beta[i % 3] * p[i];
  }
  return run;
}

// z = (beta^2 + L)^-1 (scale_in r) scaled by scale_out, per pixel, through the library's DCT.
void dct_precondition(int W, int H, double beta2, const Vec& scale_in, const Vec& scale_out,
                      const Vec& r, Vec& z) {
  const size_t px = size_t(W) * H;
  Vec data(3 * px);
  static Vec zeros;
  zeros.assign(3 * px, 0.f);
  for (size_t i = 0; i < 3 * px; ++i) data[i] = float(scale_in[i / 3] * r[i] / beta2);
  const detail::CachedDctBuffer planes(3 * px);
  detail::solve_l2_dct_rows(W, H, std::sqrt(beta2), data.data(), zeros.data(), zeros.data(),
                            planes.get(), true, [&](int y, const double* const* rows) {
                              for (int x = 0; x < W; ++x) {
                                const size_t i = size_t(y) * W + x;
                                for (int c = 0; c < 3; ++c)
                                  z[3 * i + c] = float(rows[c][x]) * scale_out[i];
                              }
                            });
}

double percentile_spread(const Vec& wx, const Vec& wy) {
  Vec w;
  for (float v : wx)
    if (v > 0) w.push_back(v);
  for (float v : wy)
    if (v > 0) w.push_back(v);
  if (w.empty()) return 0.0;
  const size_t lo = w.size() / 100, hi = w.size() - 1 - w.size() / 100;
  std::nth_element(w.begin(), w.begin() + lo, w.end());
  const float a = w[lo];
  std::nth_element(w.begin(), w.begin() + hi, w.end());
  return double(w[hi]) / a;
}

}  // namespace

std::vector<PcgProbeRow> probe_l1_pcg(const PcgProbeProblem& problem,
                                      const std::vector<int>& probe_at, double tolerance,
                                      int max_steps, bool dct) {
  const int W = problem.width, H = problem.height;
  const size_t px = size_t(W) * H;
  ReconstructionInput in{W,       H,      problem.primal, problem.gradient_x, problem.gradient_y,
                         nullptr, nullptr};
  ReconstructionSettings l2;
  l2.norm = ReconstructionNorm::L2;
  l2.alpha = problem.alpha;
  l2.fft_measure = true;
  l2.threads = 0;
  Vec x = reconstruct(in, l2);

  Vec w0(px), wx(px), wy(px), inv(px);
  detail::CgWorkspace ws;
  ws.resize(3 * px);
  const detail::IrlsData data{
      W, H, problem.primal, problem.gradient_x, problem.gradient_y, nullptr, problem.alpha};
  const detail::IrlsWeights out{w0.data(), wx.data(), wy.data(), inv.data()};
  detail::WeightedProblem pb{
      W,         H,         problem.primal, problem.gradient_x, problem.gradient_y,
      w0.data(), wx.data(), wy.data(),      inv.data(),         nullptr};
  // The library's schedule (reconstruct.cpp): 36 reweightings, reg 0.05 -> 0.05 / 2^19,
  // 12 -> 3 steps.
  const int K = 36, first = 12, last = 3;
  const double reg0 = 0.05, reg1 = 0.05 / 524288.0;
  const double decay = std::pow(reg1 / reg0, 1.0 / (K - 1));
  double reg = reg0;
  std::vector<PcgProbeRow> rows;
  for (int k = 0; k < K; ++k, reg *= decay) {
    const auto start = detail::irls_reweight(data, float(reg), x.data(), out, ws.r.data(), true);
    const int steps = int(std::lround(first + double(last - first) * k / (K - 1)));
    const Vec x0 = x;
    const auto cg = detail::solve_weighted_cg_from_residual(pb, x.data(), start, steps, 0.0, ws);
    if (std::find(probe_at.begin(), probe_at.end(), k) == probe_at.end()) continue;

    PcgProbeRow row;
    row.reweighting = k;
    row.library_steps = steps;
    row.jacobi_residual = cg.relative_residual;
    row.weight_spread = percentile_spread(wx, wy);
    // Scalar weights: means over the present terms.
    double s0 = 0, sg = 0, n0 = 0, ng = 0;
    for (size_t i = 0; i < px; ++i) {
      s0 += w0[i], n0 += w0[i] > 0;
      if (wx[i] > 0) sg += wx[i], ng += 1;
      if (wy[i] > 0) sg += wy[i], ng += 1;
    }
    const double mean_g = sg / ng, beta2 = (s0 / n0) / mean_g;
    const Vec ones(px, 1.f), inv_mean(px, float(1.0 / mean_g));
    Vec d_half(px);  // D^-1/2 with D = diag(A) / (beta^2 + 4)
    for (size_t i = 0; i < px; ++i)
      d_half[i] = inv[i] > 0 ? float(std::sqrt(inv[i] * (beta2 + 4.0))) : 0.f;
    const Preconditioner jacobi = [&](const Vec& r, Vec& z) {
      for (size_t i = 0; i < 3 * px; ++i) z[i] = inv[i / 3] * r[i];
    };
    const Preconditioner scalar = [&](const Vec& r, Vec& z) {
      dct_precondition(W, H, beta2, ones, inv_mean, r, z);
    };
    const Preconditioner scaled = [&](const Vec& r, Vec& z) {
      dct_precondition(W, H, beta2, d_half, d_half, r, z);
    };
    detail::MultigridOptions options[4];
    for (int v = 0; v < 4; ++v) {
      options[v].form =
          v % 2 ? detail::MultigridOptions::kVCycle : detail::MultigridOptions::kAdditive;
      options[v].edge_scale = v < 2 ? 0.5f : 1.f;
    }
    detail::WeightedMultigrid mg[4] = {
        detail::WeightedMultigrid(options[0]), detail::WeightedMultigrid(options[1]),
        detail::WeightedMultigrid(options[2]), detail::WeightedMultigrid(options[3])};
    Preconditioner multigrid[4];
    for (int v = 0; v < 4; ++v) {
      mg[v].build(pb);
      multigrid[v] = [&mg, v](const Vec& r, Vec& z) { mg[v].apply(r.data(), z.data()); };
    }
    const Preconditioner* all[PcgProbeRow::kPreconditioners] = {
        &jacobi, &scalar, &scaled, &multigrid[0], &multigrid[1], &multigrid[2], &multigrid[3]};
    for (int m = 0; m < PcgProbeRow::kPreconditioners; ++m) {
      if (!dct && (m == 1 || m == 2)) {
        row.steps_to_library[m] = row.steps_to_tolerance[m] = -1;
        continue;
      }
      const PcgRun run = run_pcg(pb, x0, *all[m], row.jacobi_residual, tolerance, max_steps);
      row.steps_to_library[m] = run.to_first;
      row.steps_to_tolerance[m] = run.to_second;
      row.seconds_to_tolerance[m] = run.seconds_to_second;
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace gdpt::bench
