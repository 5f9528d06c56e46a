// Exact L2 screened Poisson solve by the 2-D DCT (Bhat et al. 2008, "Fourier analysis of the 2D
// screened Poisson equation for gradient domain problems").
//
// With forward differences and Neumann rows at the last column / row, the normal-equation
// operator  alpha^2 + Dx^T Dx + Dy^T Dy  has the DCT-II basis as eigenvectors, with eigenvalues
//   alpha^2 + (2 - 2 cos(pi kx / W)) + (2 - 2 cos(pi ky / H)).
// So  I = DCT-III( DCT-II(b) / eigenvalue ) / (4 W H)  with  b = alpha^2 primal + Dx^T dx + Dy^T
// dy. The solve runs in double precision: with alpha -> 1e-4 the DC term is alpha^2 * sum(primal)
// next to O(1) divergence values, which float cannot hold.
//
// FFTW plans (for the solve: single-threaded 1-D real DFTs behind real_fft_dct.h's DCTs; for
// the benchmark's reference: 2-D REDFT10 / REDFT01) are created once per (size[, threads],
// effort) and cached for the life of the process; FFTW_MEASURE plans also load and save FFTW wisdom
// in $XDG_CACHE_HOME/gdpt/fftw-wisdom (or ~/.cache/gdpt/fftw-wisdom).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>

namespace gdpt::detail {

// Double buffer for the DCT planes: 2 MiB aligned and advised for transparent huge pages
// (core/huge_pages.h), which also satisfies FFTW's SIMD alignment (that of the planning
// buffer).
struct DctFree {
  void operator()(double* p) const;
};
using DctBuffer = std::unique_ptr<double[], DctFree>;
DctBuffer dct_alloc(size_t count);

// A dct_alloc buffer of `count` doubles for one solve, taken from and given back to a one-slot
// cache: repeated solves of one size (the add-on, the compositor node, benchmarks) reuse the
// memory instead of mapping and zeroing 50 MB (1080p) anew each time. The cache keeps the
// buffer of the last solve for the life of the process; concurrent solves each get their own.
class CachedDctBuffer {
 public:
  explicit CachedDctBuffer(size_t count);
  ~CachedDctBuffer();
  CachedDctBuffer(const CachedDctBuffer&) = delete;
  CachedDctBuffer& operator=(const CachedDctBuffer&) = delete;
  double* get() const { return buffer_.get(); }

 private:
  size_t count_;
  DctBuffer buffer_;
};

// Inputs are interleaved RGB floats. `planes` holds 3 planes of width * height doubles (from
// dct_alloc) and receives the solution per channel. Returns false, with `planes` unspecified, when
// any input value (including the ignored last column of dx and last row of dy) is not finite: the
// finiteness check is part of the pass that forms the right-hand side.
//
// The 2-D transforms are done as 1-D DCTs (real_fft_dct.h) inside three passes over memory, run in
// the caller's TBB arena (fixed blocks: the result does not depend on the thread count):
//   1. per row: b, the finiteness check, forward DCT along the row;
//   2. per block of 8 columns: forward DCT along the columns, division by the eigenvalues,
//      inverse DCT along the columns;
//   3. per row: inverse DCT along the row, then the row is handed on.
bool solve_l2_dct(int width, int height, double alpha, const float* primal, const float* gradient_x,
                  const float* gradient_y, double* planes, bool measure);

// The same solve, but each solution row y goes to sink(y, rows) (rows[c]: `width` doubles of
// channel c) instead of back into `planes`, which is then only scratch. Called from the row
// pass's threads, each row once.
using RowSink = std::function<void(int y, const double* const* rows)>;
bool solve_l2_dct_rows(int width, int height, double alpha, const float* primal,
                       const float* gradient_x, const float* gradient_y, double* planes,
                       bool measure, const RowSink& sink);

// One forward (REDFT10) and one inverse (REDFT01) 2-D transform of the 3 planes, unnormalised,
// through cached FFTW 2-D plans (3 planes per plan, `threads` FFTW threads): the benchmark's
// reference cost.
void dct_round_trip(int width, int height, double* planes, int threads, bool measure);

// Path of the FFTW wisdom file used by FFTW_MEASURE plans.
std::string fftw_wisdom_path();

}  // namespace gdpt::detail
