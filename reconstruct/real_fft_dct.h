// DCT-II and DCT-III of real lines through real FFTs (Makhoul 1980, "A fast cosine transform in
// one and multiple dimensions"), with FFTW's unnormalised REDFT10 / REDFT01 conventions:
//   forward  X[k] = 2 sum_n x[n] cos(pi (2n + 1) k / 2N)
//   inverse  x[n] = X[0] + 2 sum_{k>0} X[k] cos(pi k (2n + 1) / 2N)   (inverse(forward(x)) = 2N x)
// The even samples in order, then the odd ones reversed, have an N-point DFT V with
// X[k] = 2 Re(w_k V[k]) and X[N-k] = -2 Im(w_k V[k]), w_k = exp(-i pi k / 2N); the inverse
// undoes those steps. An N-point real FFT plus O(N) twiddles is about twice as fast here as
// FFTW's REDFT kinds, which FFTW computes through a real DFT of twice the work.
#pragma once

#include <fftw3.h>

#include <vector>

namespace gdpt::detail {

class RealFftDct {
 public:
  // Plans for `howmany` contiguous lines of length n. Not thread-safe (FFTW's planner): the
  // caller holds its planner lock. Executing is thread-safe with per-thread Work.
  RealFftDct(int n, int howmany, unsigned fftw_flags);
  ~RealFftDct();
  RealFftDct(const RealFftDct&) = delete;
  RealFftDct& operator=(const RealFftDct&) = delete;

  // Per-thread buffers with FFTW's alignment (that of the planning buffers).
  struct Work {
    double* real = nullptr;
    fftw_complex* spectrum = nullptr;
    explicit Work(const RealFftDct& dct);
    ~Work();
    Work(const Work&) = delete;
    Work& operator=(const Work&) = delete;
  };

  // In place on `lines` (howmany lines of n values, one after the other).
  void forward(double* lines, Work& work) const;
  void inverse(double* lines, Work& work) const;

 private:
  int n_ = 0, howmany_ = 1, bins_ = 1;  // bins_ = n / 2 + 1 spectrum values per line
  fftw_plan r2c_ = nullptr, c2r_ = nullptr;
  std::vector<double> cos_, sin_;  // of pi k / 2n, k < bins_
};

}  // namespace gdpt::detail
