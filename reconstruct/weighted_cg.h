// Conjugate gradients on the weighted screened Poisson normal equations
//   (W0 + Dx^T Wx Dx + Dy^T Wy Dy) I = W0 primal + Dx^T Wx dx + Dy^T Wy dy,
// one independent CG per RGB channel (same operator, own step sizes), the three run in lockstep
// through the same passes. The weights are per pixel and shared by the channels: W0 already holds
// alpha^2; Wx must be zero in the last column and Wy in the last row (Neumann).
//
// With a Jacobi preconditioner the same passes run PCG (z = D^-1 r is formed on the fly).
// Vectors are interleaved RGB float (memory bandwidth is the limit of every pass); reductions are
// in double and deterministic (see parallel.h). One CG step is two passes over memory:
//   1. p = r + beta p and q = A p fused (p's neighbours are formed on the fly), with <p, q>;
//   2. x += a p, r -= a q, with <r, r>.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace gdpt::detail {

struct WeightedProblem {
  int width = 0, height = 0;
  const float* primal = nullptr;      // RGB, finite
  const float* gradient_x = nullptr;  // RGB, finite
  const float* gradient_y = nullptr;  // RGB, finite
  const float* w0 = nullptr;          // per pixel, alpha^2 included
  const float* wx = nullptr;          // per pixel, zero in the last column
  const float* wy = nullptr;          // per pixel, zero in the last row
  // Optional Jacobi preconditioner: 1 / diag(A) per pixel (0 where the row of A is empty).
  // nullptr runs plain CG.
  const float* inv_diagonal = nullptr;
};

// 1 / diag(A) for the problem's weights (0 where diag(A) is 0), `width * height` values.
std::vector<float> jacobi_inverse_diagonal(const WeightedProblem& problem);

struct CgWorkspace {
  std::vector<float> r, p, p_next, q;
  void resize(size_t values);  // no-op when already that size
};

struct CgResult {
  int iterations = 0;
  double relative_residual = 0.0;  // max over channels of |r_c| / |b_c| at exit
};

// Runs CG from `x` (RGB, width * height * 3) until every channel has |r_c| <= tolerance |b_c| or
// `max_iterations` steps were taken (tolerance 0: exactly max_iterations steps).
CgResult solve_weighted_cg(const WeightedProblem& problem, float* x, int max_iterations,
                           double tolerance, CgWorkspace& workspace);

// The sums of a starting residual r = b - A x, per channel: |r_c|^2, |b_c|^2 and <r_c, z_c>
// (z = D^-1 r; equal to |r_c|^2 for plain CG).
struct CgStart {
  std::array<double, 3> rr{}, bb{}, rz{};
};

// As solve_weighted_cg, for a caller that has already formed r = b - A x in `workspace.r`
// (resized with workspace.resize) together with its sums, e.g. in the pass that made the weights.
CgResult solve_weighted_cg_from_residual(const WeightedProblem& problem, float* x,
                                         const CgStart& start, int max_iterations, double tolerance,
                                         CgWorkspace& workspace);

// |b - A x| / |b| per channel, maximum over the channels (in double; for tests and reports).
double weighted_relative_residual(const WeightedProblem& problem, const float* x);

}  // namespace gdpt::detail
