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

// A preconditioner other than Jacobi: z = M^-1 r with M symmetric positive definite (so that CG
// stays valid), e.g. the multigrid V-cycle of multigrid.h.
class CgPreconditioner {
 public:
  virtual ~CgPreconditioner() = default;
  // z = M^-1 r for RGB vectors of the problem's size; returns <r_c, z_c> per channel.
  virtual std::array<double, 3> apply(const float* r, float* z) = 0;

  // Optional additive two-level form  z = D^-1 r + scale P zc  (D^-1 the problem's Jacobi
  // diagonal, P constant on 2x2 pixel blocks), which CG fuses into its own passes instead of
  // calling apply(): its update pass sums r over the blocks into `r` (rc = P^T r, restrict_row),
  // solve_coarse() then forms zc = M_c^-1 rc in `z` and returns <rc_c, zc_c>, and its direction
  // pass adds scale P zc. nullptr: CG calls apply().
  struct Coarse {
    float* r = nullptr;
    const float* z = nullptr;
    int width = 0;
    float scale = 1.f;
  };
  virtual const Coarse* coarse() const { return nullptr; }
  virtual std::array<double, 3> solve_coarse() { return {}; }
};

// P^T of the 2x2 block aggregation, one fine row at a time: adds row y of v - a (a == nullptr: v;
// RGB, `width` pixels) into row y / 2 of rc (RGB, `coarse_width` = (width + 1) / 2 pixels), which
// is zeroed first at even y: go through a coarse row's fine rows in order, from an even row.
void restrict_row(int width, int y, const float* v, const float* a, float* rc, int coarse_width);

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
  // Optional preconditioner used instead of the Jacobi one (z = M^-1 r is then stored, one more
  // vector and pass; a fixed-step solve skips it after the last step).
  CgPreconditioner* preconditioner = nullptr;
};

// 1 / diag(A) for the problem's weights (0 where diag(A) is 0), `width * height` values.
std::vector<float> jacobi_inverse_diagonal(const WeightedProblem& problem);

struct CgWorkspace {
  std::vector<float> r, p, p_next, q;
  std::vector<float> z;        // only with a WeightedProblem::preconditioner
  void resize(size_t values);  // no-op when already that size (z is sized when first needed)
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
