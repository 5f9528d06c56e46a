// An L1 solver probe for bench_reconstruct --admm: ADMM (split Bregman) whose every iteration is
// one DCT screened Poisson solve (reconstruct/dct_solver.h), measured against the library's IRLS
// L1 (issue 30 asks whether it can reach IRLS's objective in far less time). Not part of the
// library: the measurements in bench/results/l1_admm_probe.txt say why.
//
// The objective  sum_px alpha |I - primal|_RGB + |Dx I - dx|_RGB + |Dy I - dy|_RGB  (reconstruct.h)
// is split as z_k = A_k I - b_k for the three terms k (A_0 = identity, b_0 = primal; A_x = Dx,
// b_x = dx; A_y = Dy, b_y = dy). With scaled duals u_k and penalties rho alpha^2 (primal term) and
// rho (gradients), one iteration is
//   1. I = argmin alpha^2 |I - t_0|^2 + |Dx I - t_x|^2 + |Dy I - t_y|^2 with t = b + z - u: the
//      L2 problem of dct_solver.h with the targets as its data, solved exactly;
//   2. h_k = relaxation (A_k I - b_k) + (1 - relaxation) z_k, z_k = group shrinkage of h_k + u_k
//      by 1 / (rho s_k) (s_0 = alpha, s_x = s_y = 1), u_k += h_k - z_k, next t_k = b_k + z_k - u_k;
//      one pass over memory, which also sums the objective of the current I.
// Finite inputs only (the benchmark's): missing data is not handled.
// rho = 1 / (threshold_per_residual x the mean gradient residual of the start): scale-free.
// Start: z = A I - b and u = (threshold) e / |e|, the dual that makes the start a fixed point of
// the shrinkage. Stop: the objective changed by less than `tolerance` (relative) over the last
// iteration and the primal residual sum |A I - b - z| is below 10 x tolerance x the objective, or
// max_iterations solves were made.
#pragma once

#include <cstdint>
#include <vector>

namespace gdpt::bench {

struct AdmmProblem {
  int width = 0, height = 0;
  const float* primal = nullptr;      // RGB, finite
  const float* gradient_x = nullptr;  // RGB, finite
  const float* gradient_y = nullptr;  // RGB, finite
  double alpha = 1.0;
};

struct AdmmOptions {
  int max_iterations = 30;
  double tolerance = 0.0;  // 0: exactly max_iterations solves
  double relaxation = 1.7;
  double threshold_per_residual = 1.0;
};

struct AdmmResult {
  int iterations = 0;              // DCT solves made
  std::vector<double> objectives;  // of the start, then of every iterate
  std::vector<double> seconds;     // wall time from the call to each objective
};

// Minimises from `x` (RGB, in place): the L2 solution for a cold start, an L1 solution of the
// same passes at another alpha for a warm start.
AdmmResult solve_l1_admm(const AdmmProblem& problem, float* x, const AdmmOptions& options);

}  // namespace gdpt::bench
