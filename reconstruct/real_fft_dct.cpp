#include "reconstruct/real_fft_dct.h"

#include <cmath>
#include <new>
#include <stdexcept>

namespace gdpt::detail {

RealFftDct::RealFftDct(int n, int howmany, unsigned fftw_flags)
    : n_(n), howmany_(howmany), bins_(n / 2 + 1), cos_(size_t(n / 2 + 1)), sin_(size_t(n / 2 + 1)) {
  for (int k = 0; k < bins_; ++k) {
    const double a = M_PI * k / (2.0 * n);
    cos_[size_t(k)] = std::cos(a);
    sin_[size_t(k)] = std::sin(a);
  }
  const Work scratch(*this);
  r2c_ = fftw_plan_many_dft_r2c(1, &n_, howmany, scratch.real, nullptr, 1, n, scratch.spectrum,
                                nullptr, 1, bins_, fftw_flags);
  c2r_ = fftw_plan_many_dft_c2r(1, &n_, howmany, scratch.spectrum, nullptr, 1, bins_, scratch.real,
                                nullptr, 1, n, fftw_flags);
  if (!r2c_ || !c2r_) throw std::runtime_error("FFTW could not create a real DFT plan");
}

RealFftDct::~RealFftDct() {
  if (r2c_) fftw_destroy_plan(r2c_);
  if (c2r_) fftw_destroy_plan(c2r_);
}

RealFftDct::Work::Work(const RealFftDct& dct)
    : real(static_cast<double*>(fftw_malloc(sizeof(double) * size_t(dct.n_) * dct.howmany_))),
      spectrum(static_cast<fftw_complex*>(
          fftw_malloc(sizeof(fftw_complex) * size_t(dct.bins_) * dct.howmany_))) {
  if (!real || !spectrum) {
    fftw_free(real);
    fftw_free(spectrum);
    throw std::bad_alloc();
  }
}

RealFftDct::Work::~Work() {
  fftw_free(real);
  fftw_free(spectrum);
}

void RealFftDct::forward(double* lines, Work& work) const {
  const int n = n_;
  // --- Even samples in order, odd samples reversed ---
  for (int j = 0; j < howmany_; ++j) {
    const double* x = lines + size_t(j) * n;
    double* v = work.real + size_t(j) * n;
    for (int i = 0; 2 * i < n; ++i) v[i] = x[2 * i];
    for (int i = 0; 2 * i + 1 < n; ++i) v[n - 1 - i] = x[2 * i + 1];
  }
  fftw_execute_dft_r2c(r2c_, work.real, work.spectrum);
  // --- Twiddle: X[k] = 2 Re(w_k V_k), X[n-k] = -2 Im(w_k V_k) ---
  for (int j = 0; j < howmany_; ++j) {
    double* X = lines + size_t(j) * n;
    const fftw_complex* V = work.spectrum + size_t(j) * bins_;
    X[0] = 2.0 * V[0][0];
    for (int k = 1; k < bins_; ++k) {
      const double c = cos_[size_t(k)], s = sin_[size_t(k)];
      const double re = V[k][0], im = V[k][1];
      X[k] = 2.0 * (c * re + s * im);
      if (n - k != k) X[n - k] = -2.0 * (c * im - s * re);
    }
  }
}

void RealFftDct::inverse(double* lines, Work& work) const {
  const int n = n_;
  // --- Spectrum: V_k = conj(w_k) (X[k] - i X[n-k]), which is twice the forward's V_k ---
  for (int j = 0; j < howmany_; ++j) {
    const double* X = lines + size_t(j) * n;
    fftw_complex* V = work.spectrum + size_t(j) * bins_;
    V[0][0] = X[0];
    V[0][1] = 0.0;
    for (int k = 1; k < bins_; ++k) {
      const double c = cos_[size_t(k)], s = sin_[size_t(k)];
      const double a = X[k], b = X[n - k];
      V[k][0] = c * a + s * b;
      V[k][1] = s * a - c * b;
    }
  }
  fftw_execute_dft_c2r(c2r_, work.spectrum, work.real);
  // --- Undo the reordering (the unnormalised c2r supplies the 2n of REDFT01 o REDFT10) ---
  for (int j = 0; j < howmany_; ++j) {
    double* x = lines + size_t(j) * n;
    const double* v = work.real + size_t(j) * n;
    for (int i = 0; 2 * i < n; ++i) x[2 * i] = v[i];
    for (int i = 0; 2 * i + 1 < n; ++i) x[2 * i + 1] = v[n - 1 - i];
  }
}

}  // namespace gdpt::detail
