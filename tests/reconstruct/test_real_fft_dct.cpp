// RealFftDct (Makhoul's DCT through real FFTs) against FFTW's own REDFT10 / REDFT01 on the same
// lines: odd, even, prime and the 1080p sizes, one line and a block of lines.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <fftw3.h>

#include "reconstruct/real_fft_dct.h"

namespace gdpt::detail {
namespace {

// FFTW's REDFT kind of each line of `lines` (n values each), the oracle.
std::vector<double> fftw_redft(std::vector<double> lines, int n, fftw_r2r_kind kind) {
  std::vector<double> line(size_t(n), 0.0);
  fftw_plan plan = fftw_plan_r2r_1d(n, line.data(), line.data(), kind, FFTW_ESTIMATE);
  for (size_t off = 0; off < lines.size(); off += size_t(n)) {
    std::copy_n(lines.begin() + long(off), n, line.begin());
    fftw_execute(plan);
    std::copy_n(line.begin(), n, lines.begin() + long(off));
  }
  fftw_destroy_plan(plan);
  return lines;
}

double max_abs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::fabs(x));
  return m;
}

TEST(RealFftDct, MatchesFftwRedftKinds) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n : {1, 2, 3, 4, 5, 8, 17, 64, 1080, 1920})
    for (int howmany : {1, 8}) {
      std::vector<double> x(size_t(n) * howmany);
      for (double& v : x) v = u(rng);
      const RealFftDct dct(n, howmany, FFTW_ESTIMATE);
      RealFftDct::Work work(dct);

      std::vector<double> fwd = x;
      dct.forward(fwd.data(), work);
      const std::vector<double> fwd_ref = fftw_redft(x, n, FFTW_REDFT10);
      std::vector<double> inv = x;
      dct.inverse(inv.data(), work);
      const std::vector<double> inv_ref = fftw_redft(x, n, FFTW_REDFT01);

      double err_f = 0.0, err_i = 0.0;
      for (size_t i = 0; i < x.size(); ++i) {
        err_f = std::max(err_f, std::fabs(fwd[i] - fwd_ref[i]));
        err_i = std::max(err_i, std::fabs(inv[i] - inv_ref[i]));
      }
      EXPECT_LE(err_f, 1e-12 * max_abs(fwd_ref)) << "forward, n " << n << " x " << howmany;
      EXPECT_LE(err_i, 1e-12 * max_abs(inv_ref)) << "inverse, n " << n << " x " << howmany;

      // inverse(forward(x)) = 2n x, as FFTW's REDFT01 o REDFT10.
      dct.inverse(fwd.data(), work);
      double err_r = 0.0;
      for (size_t i = 0; i < x.size(); ++i)
        err_r = std::max(err_r, std::fabs(fwd[i] / (2.0 * n) - x[i]));
      EXPECT_LE(err_r, 1e-12) << "round trip, n " << n << " x " << howmany;
    }
}

}  // namespace
}  // namespace gdpt::detail
