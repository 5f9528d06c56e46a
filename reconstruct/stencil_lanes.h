// The IRLS five-point stencil on groups of interleaved RGB pixels, shared by the CG kernels and
// the multigrid cycle: lane k of a group is channel k % 3 of pixel k / 3, so the compiler
// vectorises the lanes.
#pragma once

namespace gdpt::detail {

inline constexpr int kGroup = 4, kLanes = 3 * kGroup;

struct StencilLanes {
  float a0[kLanes], ax[kLanes], axl[kLanes], ay[kLanes], ayu[kLanes];

  // The weights of the group starting at pixel x, which has both x-neighbours: w0 the primal
  // term's, wx the edge to the right, wy the edge below and wyu the edge above.
  void gather(const float* w0, const float* wx, const float* wy, const float* wyu, int x) {
    for (int k = 0; k < kLanes; ++k) {
      const int xk = x + k / 3;
      a0[k] = w0[xk];
      ax[k] = wx[xk];
      axl[k] = wx[xk - 1];
      ay[k] = wy[xk];
      ayu[k] = wyu[xk];
    }
  }
  // Lane k of A v: v the group's values, vd and vu those of the rows below and above.
  float apply(int k, const float* v, const float* vd, const float* vu) const {
    const float c = v[k];
    return a0[k] * c + ax[k] * (c - v[k + 3]) + axl[k] * (c - v[k - 3]) + ay[k] * (c - vd[k]) +
           ayu[k] * (c - vu[k]);
  }
};

}  // namespace gdpt::detail
