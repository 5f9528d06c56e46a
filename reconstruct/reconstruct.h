// Screened Poisson reconstruction of an image from a noisy primal and its noisy gradients:
//   minimise || alpha (I - primal) ||_p^p + || Dx I - dx ||_p^p + || Dy I - dy ||_p^p
// with forward differences and zero (Neumann) rows at the last column / row, per RGB channel.
// Images are interleaved RGB float, `width * height * 3`, in rows as stored (the gradient
// convention dy(x, y) = I(x, y + 1) - I(x, y) refers to those rows).
//
// Norms (docs/reconstruct.md has the details and the benchmark):
//   L2        exact direct solve by the 2-D DCT, in double precision.
//   L1        IRLS from the L2 solution. The L1 term of a pixel is the Euclidean norm of its RGB
//             residual (the reweighting weights are shared across RGB, so this is the objective
//             they minimise): objective = sum_px alpha |I - primal|_RGB + |Dx I - dx|_RGB + |Dy I -
//             dy|_RGB.
//   Weighted  Rousselle et al. 2016: every squared term weighted by the inverse of its per-pixel
//             variance (floored), the primal term also by alpha^2 (alpha = 1 is the maximum-
//             likelihood weighting); Jacobi-preconditioned CG from the L2 solution to
//             `weighted_tolerance`.
//   None      primal (+ emission).
//   Feature   feature-guided edge-aware filters of the gradient-domain solution (feature_guide),
//             chosen per pixel by an error estimate from two halves of the samples,
//             each with its own gradient-domain solve (feature_reconstruct.h).
// Non-finite inputs are missing data: a term (primal, dx or dy of a pixel) with any non-finite
// channel gets zero weight. The output is always finite.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace gdpt {

enum class ReconstructionNorm : uint8_t { L2, L1, Weighted, None, Feature };

// Preconditioner of L1's inner solves: Jacobi, or a multigrid V-cycle whose coarse operators
// follow the IRLS weights (reconstruct/multigrid.h), at the finest level additive (D^-1 plus the
// coarse correction) or a full V(1,1).
enum class L1Preconditioner : uint8_t { Jacobi, MultigridAdditive, MultigridVCycle };

// Buffers that consecutive solves can share (ReconstructionSettings::scratch).
struct ReconstructionScratch;

struct ReconstructionSettings {
  ReconstructionNorm norm = ReconstructionNorm::L1;
  float alpha = 0.2f;  // must be > 0
  int threads = 0;     // 0 = all cores

  // L1 (cold): reweightings, and inner PCG steps per reweighting, falling linearly from the first
  // to the last reweighting; the first l1_multigrid_reweightings are preconditioned by a multigrid
  // V-cycle, the rest by Jacobi (chosen with bench_reconstruct --schedules on the benchmark and
  // the outlier data, --l1d; docs/reconstruct.md). use_jacobi_l1_schedule() sets the earlier
  // Jacobi-only default (36 x 12 -> 3).
  int l1_reweightings = 30;
  int l1_cg_steps_first = 3;
  int l1_cg_steps_last = 1;
  // Preconditioner of the cold inner solves (warm solves use Jacobi) and, for multigrid, the scale
  // of its coarse correction and of its coarse edges (multigrid.h; bench_reconstruct --schedules
  // K,F,L,P,S,E,U).
  L1Preconditioner l1_preconditioner = L1Preconditioner::MultigridVCycle;
  float l1_multigrid_coarse_scale = 1.f;
  float l1_multigrid_edge_scale = 1.f;
  // Multigrid only for the first this many reweightings (negative: all), Jacobi after: the late
  // IRLS weights spread over 4-6 orders of magnitude, where 2x2 aggregation stops paying
  // (bench_reconstruct --pcg-mg).
  int l1_multigrid_reweightings = 16;
  // L1 warm start (ReconstructionInput::initial): reweightings and Jacobi-PCG steps per reweighting
  // (bench_reconstruct --warm --sweep). The regulariser falls from l1_warm_regulariser to the cold
  // schedule's last value, so a start near the minimum is not first pulled towards the smoothed
  // problem's solution.
  int l1_warm_reweightings = 4;
  int l1_warm_cg_steps = 4;
  double l1_warm_regulariser = 0.05 / 512.0;
  // Weighted (and L2 with missing data): stop at |b - A I| <= tolerance |b| per channel.
  double weighted_tolerance = 1e-4;
  int max_cg_iterations = 2000;
  // FFTW_MEASURE plans (kept as wisdom in ~/.cache/gdpt/fftw-wisdom): worth it when the same size
  // is solved repeatedly in one process (the add-on); FFTW_ESTIMATE otherwise.
  bool fft_measure = false;
  // Fill ReconstructionReport::objective (one more pass over all buffers). Off by default: the
  // engine and the compositor node never read it; the CLI prints it, tests and benchmarks check it.
  bool compute_objective = false;
  // Feature: the gradient-domain solution that is filtered (L1, L2, Weighted at `alpha`, or None:
  // the primal is filtered).
  ReconstructionNorm feature_guide = ReconstructionNorm::L1;
  // Feature with the L1 guide: its reweightings (the Jacobi schedule's steps, 12 falling to 3).
  // The filters need no fully converged L1. Geometric mean L1 / Feature over the report's 28
  // renders (bench/reconstruct/feature_resolve.py): 3.51 at 6, 3.45 at 8, 3.30 at 12; fewer
  // cost glass_caustics at 40 s (7.32x at 12, 6.67x at 8, 6.18x at 6).
  int feature_guide_l1_reweightings = 8;
  // Feature: each half (for the error estimates) is solved by the guide's norm, with the L1 guide
  // at this many reweightings (2: 12 + 3 Jacobi-PCG steps): the filters are judged on images like
  // the one they are applied to. Geometric mean as above, with the guide at 12: 3.30 at 2, 3.24
  // at 1, 3.31 at 4, 3.28 at 8; 3.08 with fewer steps (1 reweighting of 4, 2 of 3).
  int feature_halves_l1_reweightings = 2;
  // Feature, given the variance buffer and gradient halves, with a guide other than Weighted: one
  // more candidate, the Weighted solution itself: each half's, with the variances of all samples,
  // feature_weighted_cg_steps Jacobi-PCG steps from the half's guide-norm solution, and their mean
  // for all samples. Per-pixel variances weigh primal and gradients where one alpha cannot
  // (bump-mapped textures); docs/reconstruct.md. Steps 8 / 15 / 30: geometric mean 3.28 /
  // 3.30 / 3.30 (guide at 12).
  bool feature_weighted_candidate = true;
  int feature_weighted_cg_steps = 15;
  // Called with the completed fraction in [0, 1] (from the calling thread).
  std::function<void(float)> progress;
  // Optional buffers shared by a sequence of solves of one image size, one at a time (the
  // Feature norm's guide, halves and Weighted solves): CG vectors and per-pixel weights stay
  // allocated between them instead of being freed and first-touched again. Same results.
  std::shared_ptr<ReconstructionScratch> scratch;
};

std::shared_ptr<ReconstructionScratch> make_reconstruction_scratch();

// The cold L1 schedule that was the default before the multigrid one: 36 reweightings of 12 -> 3
// Jacobi-PCG steps (270 inner steps; 1.6-1.8x the CPU time of the multigrid default at 1080p).
inline void use_jacobi_l1_schedule(ReconstructionSettings& s) {
  s.l1_reweightings = 36;
  s.l1_cg_steps_first = 12;
  s.l1_cg_steps_last = 3;
  s.l1_preconditioner = L1Preconditioner::Jacobi;
}

struct ReconstructionInput {
  int width = 0, height = 0;
  const float* primal = nullptr;      // RGB
  const float* gradient_x = nullptr;  // RGB
  const float* gradient_y = nullptr;  // RGB
  const float* variance = nullptr;    // 3 per pixel (primal, dx, dy luminance); Weighted only
  const float* emission = nullptr;    // RGB, optional: added to the solution

  // Feature norm. The primal as two halves (the engine's even / odd samples), each the mean
  // of its half's samples, both required; `primal` may then be null (the halves' mean is used).
  const float* primal_a = nullptr;    // RGB
  const float* primal_b = nullptr;    // RGB
  const float* variance_a = nullptr;  // RGB variance of primal_a's pixel mean, optional
  const float* variance_b = nullptr;  // RGB, optional (both or none; else estimated from A - B)
  // G-PT's gradients over the same two halves of the samples (forward differences as
  // gradient_x / gradient_y), optional: with them each half gets its own gradient-domain solve,
  // which lets the error of a filtered solution be estimated from the other half.
  const float* gradient_x_a = nullptr;  // RGB
  const float* gradient_x_b = nullptr;  // RGB
  const float* gradient_y_a = nullptr;  // RGB
  const float* gradient_y_b = nullptr;  // RGB
  // Optional guide features, each with an optional per-pixel variance of its pixel mean.
  const float* albedo = nullptr;           // RGB
  const float* albedo_variance = nullptr;  // RGB
  const float* normal = nullptr;           // XYZ
  const float* normal_variance = nullptr;  // XYZ
  const float* depth = nullptr;            // 1 per pixel
  const float* depth_variance = nullptr;   // 1 per pixel

  // L1 and Weighted, optional: a previous output of reconstruct() for the same passes (emission
  // included: it is subtracted), e.g. at a nearby alpha. IRLS then starts from it with the shorter
  // warm schedule (ReconstructionSettings::l1_warm_*) instead of from the L2 solution; Weighted's
  // CG starts from it instead of from the L2 solution. Non-finite values fall back to the
  // primal's. The short schedule assumes the start is near the minimum: alpha x1.25 or x0.75
  // stays within 0.1% of a tight solve's objective, x4 does not (docs/reconstruct.md).
  const float* initial = nullptr;  // RGB
};

struct ReconstructionReport {
  int iterations = 0;      // total inner iterations
  double objective = 0.0;  // objective of the chosen norm (0 unless settings.compute_objective;
                           // always 0 for Feature, which minimises no global objective)
  double seconds = 0.0;
  double relative_residual = 0.0;  // CG exit residual |b - A I| / |b| (0 for the direct solve)
  int missing_values = 0;          // non-finite input terms treated as missing
  double guide_seconds = 0.0;      // Feature: of `seconds`, the gradient-domain solves
  // Feature: true when the primal was filtered instead of the gradient-domain solution (no
  // gradient halves in the input, or feature_guide None).
  bool feature_filtered_primal = false;
};

// Returns RGB `width * height * 3`. Throws std::invalid_argument on bad input (alpha <= 0, sizes,
// missing variance for Weighted). NaN/Inf input values are treated as missing data.
std::vector<float> reconstruct(const ReconstructionInput& input,
                               const ReconstructionSettings& settings,
                               ReconstructionReport* report = nullptr);

// The objective of `norm` (as documented above) for `image`, in double precision; missing terms
// are skipped. For Weighted, `input.variance` is required.
double reconstruction_objective(const ReconstructionInput& input, ReconstructionNorm norm,
                                float alpha, const float* image);

}  // namespace gdpt
