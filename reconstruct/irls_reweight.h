// The reweighting step of the L1 solver (IRLS), as one pass over memory.
//
// For the L1 objective  sum_px alpha |I - primal|_RGB + |Dx I - dx|_RGB + |Dy I - dy|_RGB
// each reweighting replaces every term by its quadratic majoriser at the current iterate I:
//   w0 = alpha^2 / (alpha |primal - I|_RGB + reg),  wx = 1 / (|dx - Dx I|_RGB + reg),  wy likewise,
// shared by the three channels, and solves the weighted L2 problem with Jacobi-PCG
// (weighted_cg.h). Everything that problem needs before its first CG step comes out of the same
// pass: the weights, the Jacobi inverse diagonal and the starting residual r = b - A I with its
// sums. (The residual of a pixel needs the weights of its left and upper neighbours, so the pass
// walks each chunk's rows top to bottom and carries the row above; see irls_reweight.cpp.)
#pragma once

#include <cstdint>

#include "reconstruct/weighted_cg.h"

namespace gdpt::detail {

// Which terms of a pixel take part (missing data has its bit cleared).
enum TermBits : uint8_t { kPrimalTerm = 1, kDxTerm = 2, kDyTerm = 4, kAllTerms = 7 };

struct IrlsData {
  int width = 0, height = 0;
  const float* primal = nullptr;      // RGB, finite
  const float* gradient_x = nullptr;  // RGB, finite
  const float* gradient_y = nullptr;  // RGB, finite
  const uint8_t* terms = nullptr;     // per pixel TermBits; nullptr = every term present
  float alpha = 1.f;
};

// Per-pixel outputs, width * height floats each. wx is zero in the last column and wy in the
// last row (Neumann), as WeightedProblem requires.
struct IrlsWeights {
  float* w0 = nullptr;
  float* wx = nullptr;
  float* wy = nullptr;
  float* inv_diagonal = nullptr;  // 1 / diag(A), 0 where the row of A is empty
};

// Weights for the iterate `x` (RGB) and regulariser `reg` into `out`, the residual b - A x into
// `r` (RGB), and the residual's sums for solve_weighted_cg_from_residual. |b_c|^2 is only formed
// `with_rhs` (zero otherwise): a fixed-step solve needs it for nothing but the reported relative
// residual, and it costs a fifth of the pass. Deterministic whatever the thread count.
CgStart irls_reweight(const IrlsData& data, float reg, const float* x, const IrlsWeights& out,
                      float* r, bool with_rhs);

}  // namespace gdpt::detail
