// A multigrid preconditioner for the weighted screened Poisson systems of weighted_cg.h
//   A = W0 + Dx^T Wx Dx + Dy^T Wy Dy   (per-pixel weights shared by RGB, Neumann borders),
// whose coarse operators follow the weights (IRLS spreads them over 3-6 orders of magnitude,
// which a constant-coefficient preconditioner such as the DCT solve cannot follow).
//
// Coarsening: 2x2 pixel blocks, piecewise-constant prolongation P and restriction P^T (the sum
// over a block). The Galerkin operator P^T A P is again of A's form on the (W+1)/2 x (H+1)/2
// grid: w0 summed over the block, and each coarse edge weight the sum of the fine edges crossing
// between the two blocks (edges inside a block see a constant and drop out). Every level thus
// keeps the per-pixel (w0, wx, wy) representation, rebuilt from the finer one by build().
// A block-constant P makes the Galerkin edges twice too stiff for smooth errors (the edges inside
// the blocks, in series with the crossing ones, are ignored); edge_scale 0.5 (the crossing
// edges' mean) would undo that, but measured worse than Galerkin on the IRLS systems
// (bench_reconstruct --outlier-data, bench/results/l1_multigrid.txt), so Galerkin is the default.
//
// Cycle: V(1,1) with one damped Jacobi sweep (weight omega) before and the same sweep after the
// coarse correction (scaled by coarse_scale), so M is symmetric positive definite and CG stays
// valid. The coarsest level (at most coarsest_pixels) gets symmetric Gauss-Seidel sweeps. At the
// finest level either the whole V-cycle (kVCycle: two stencil passes per application) or the
// additive form z = D^-1 r + s P V(P^T r) (kAdditive: no fine stencil beyond CG's own; CG forms
// P^T r and adds s P V in its own passes, CgPreconditioner::Coarse).
// Deterministic at any thread count: per-pixel work and chunk-ordered sums (parallel.h).
#pragma once

#include <array>
#include <vector>

#include "reconstruct/weighted_cg.h"

namespace gdpt::detail {

struct MultigridOptions {
  enum Form { kAdditive, kVCycle };
  Form form = kAdditive;
  float omega = 0.8f;        // damping of the Jacobi smoother, in (0, 1]
  float coarse_scale = 1.f;  // scale of the coarse correction, in (0, 2)
  float edge_scale = 1.f;    // coarse edge weight / sum of the crossing edges (1 = Galerkin)
  int coarsest_sweeps = 8;   // symmetric Gauss-Seidel sweeps on the coarsest level
  int coarsest_pixels = 64;  // coarsening stops at this many pixels
};

// The coarse weights of a W x H level on the (W+1)/2 x (H+1)/2 grid (see above; edge_scale 1:
// Galerkin); wx is zero in the coarse last column and wy in the coarse last row.
void coarsen_weights(int width, int height, const float* w0, const float* wx, const float* wy,
                     float edge_scale, float* coarse_w0, float* coarse_wx, float* coarse_wy);

// One level's operator: per-pixel weights and 1 / diag (0 where the row is empty).
struct MultigridGrid {
  int width = 0, height = 0;
  const float *w0 = nullptr, *wx = nullptr, *wy = nullptr, *inv = nullptr;
};

class WeightedMultigrid final : public CgPreconditioner {
 public:
  explicit WeightedMultigrid(const MultigridOptions& options = {}) : options_(options) {}
  // Builds the coarse levels from the problem's weights; call again whenever they change. The
  // problem's weights must stay alive and unchanged while apply() is used.
  void build(const WeightedProblem& problem);
  std::array<double, 3> apply(const float* r, float* z) override;
  // The additive form when the problem has a Jacobi diagonal (CG then fuses it).
  const Coarse* coarse() const override;
  std::array<double, 3> solve_coarse() override;
  int levels() const { return int(coarse_.size()) + 1; }

 private:
  using Grid = MultigridGrid;
  struct Level {
    int width = 0, height = 0;
    std::vector<float> w0, wx, wy, inv;  // per pixel
    std::vector<float> r, z;             // RGB
    Grid grid() const { return {width, height, w0.data(), wx.data(), wy.data(), inv.data()}; }
  };
  // coarse_[level].z = V-cycle applied to coarse_[level].r; returns their <r_c, z_c>.
  std::array<double, 3> cycle(size_t level);

  MultigridOptions options_;
  Grid fine_;
  std::vector<float> fine_inv_;  // when the problem has no Jacobi diagonal of its own
  std::vector<Level> coarse_;
  bool fused_ = false;
  Coarse fused_view_;
};

}  // namespace gdpt::detail
