// An L1 solver probe for bench_reconstruct --pcg: does a DCT screened-Poisson preconditioner
// (reconstruct/dct_solver.h) make the library's IRLS reweighted systems cheap enough to solve
// that L1 meets issue 30's time target? Not part of the library: bench/results/l1_pcg_probe.txt
// has the measurements that say why.
//
// The probe follows the library's IRLS trajectory (same reweighting pass, same Jacobi-PCG steps
// per reweighting) and, at chosen reweightings, solves that reweighting's weighted system
//   A = W0 + Dx^T Wx Dx + Dy^T Wy Dy
// from the same start with three preconditioners, counting the steps each needs to reach the
// residual the library's Jacobi steps reach, and a fixed relative residual:
//   Jacobi    M = diag(A) (the library's);
//   scalar    M = s (beta^2 + L), L the Neumann Laplacian, s the mean gradient weight and
//             beta^2 = mean(W0) / s: one exact DCT solve per step;
//   scaled    M^-1 = D^-1/2 (beta^2 + L)^-1 D^-1/2 with D = diag(A) / (beta^2 + 4): the same DCT
//             solve between two Jacobi scalings, so that M's diagonal matches A's;
//   mg-add    the library's multigrid (reconstruct/multigrid.h), additive at the finest level,
//             coarse edges halved (edge scale 0.5);
//   mg-V      the same, a full V(1,1) from the finest level;
//   gal-add, gal-V  the same two with Galerkin coarse operators (edge scale 1, the default).
#pragma once

#include <vector>

namespace gdpt::bench {

struct PcgProbeProblem {
  int width = 0, height = 0;
  const float* primal = nullptr;      // RGB, finite
  const float* gradient_x = nullptr;  // RGB, finite
  const float* gradient_y = nullptr;  // RGB, finite
  float alpha = 0.2f;
};

struct PcgProbeRow {
  int reweighting = 0;
  double weight_spread = 0.0;    // 99th / 1st percentile of the gradient weights
  double jacobi_residual = 0.0;  // relative residual after the library's steps
  int library_steps = 0;
  // Steps (capped) and wall seconds of each preconditioner to reach jacobi_residual, then to
  // reach `tolerance`; in the order of kNames (-1: not run or not reached).
  static constexpr int kPreconditioners = 7;
  static constexpr const char* kNames[kPreconditioners] = {"Jacobi", "scalar",  "scaled", "mg-add",
                                                           "mg-V",   "gal-add", "gal-V"};
  int steps_to_library[kPreconditioners] = {}, steps_to_tolerance[kPreconditioners] = {};
  double seconds_to_tolerance[kPreconditioners] = {};
};

// Runs the default IRLS schedule (36 reweightings, 12 -> 3 steps) and probes the reweightings in
// `probe_at`; `tolerance` is the fixed relative residual, `max_steps` the cap. Without `dct` the
// two DCT preconditioners are skipped (they cost several Jacobi steps per step).
std::vector<PcgProbeRow> probe_l1_pcg(const PcgProbeProblem& problem,
                                      const std::vector<int>& probe_at, double tolerance,
                                      int max_steps, bool dct = true);

}  // namespace gdpt::bench
