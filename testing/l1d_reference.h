// The reference "L1D" reconstruction of the G-PT reference implementation, as a yardstick for
// the L1 solver: 20 reweightings x 50 plain (unpreconditioned) CG steps starting from the primal,
// weights shared across RGB, w = 1 / (|e|_RGB + reg), reg = 0.05 halving per reweighting. It uses
// the library's fused CG passes, so comparisons measure the scheme, not the code. (The reference
// also normalises the weights to mean 1; a common factor changes nothing in CG.)
#pragma once

#include <cmath>
#include <vector>

#include "reconstruct/parallel.h"
#include "reconstruct/weighted_cg.h"

namespace gdpt::test {

// The reference L1D scheme: 20 reweightings x 50 plain CG steps starting from the primal, with
// the same fused CG passes as the library (so the comparison is about the scheme, not the code).
inline std::vector<float> l1d_reference(int W, int H, const float* primal, const float* gx,
                                        const float* gy, float alpha, int reweightings = 20,
                                        int steps = 50) {
  using gdpt::detail::parallel_rows;
  const size_t px = size_t(W) * H;
  std::vector<float> x(primal, primal + 3 * px);
  std::vector<float> w0(px), wx(px), wy(px);
  gdpt::detail::WeightedProblem pb{W,         H,         primal,    gx,      gy,
                                   w0.data(), wx.data(), wy.data(), nullptr, nullptr};
  gdpt::detail::CgWorkspace ws;
  double reg = 0.05;
  for (int k = 0; k < reweightings; ++k, reg *= 0.5) {
    parallel_rows(H, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int xx = 0; xx < W; ++xx) {
          const size_t i = size_t(y) * W + xx;
          double e0 = 0, ex = 0, ey = 0;
          for (int c = 0; c < 3; ++c) {
            const double a = x[3 * i + c] - primal[3 * i + c];
            e0 += a * a;
            if (xx + 1 < W) {
              const double b = x[3 * (i + 1) + c] - x[3 * i + c] - gx[3 * i + c];
              ex += b * b;
            }
            if (y + 1 < H) {
              const double b = x[3 * (i + W) + c] - x[3 * i + c] - gy[3 * i + c];
              ey += b * b;
            }
          }
          w0[i] = float(alpha * alpha / (alpha * std::sqrt(e0) + reg));
          wx[i] = xx + 1 < W ? float(1.0 / (std::sqrt(ex) + reg)) : 0.f;
          wy[i] = y + 1 < H ? float(1.0 / (std::sqrt(ey) + reg)) : 0.f;
        }
    });
    gdpt::detail::solve_weighted_cg(pb, x.data(), steps, 0.0, ws);
  }
  return x;
}

}  // namespace gdpt::test
