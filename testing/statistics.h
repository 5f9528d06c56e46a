// Statistics shared by the sampling tests (BSDF and light chi-square tests): the chi-square
// upper tail probability and the Sidak correction for many tests at one overall level.
#pragma once

#include <cmath>

namespace gdpt::test {

// Regularised upper incomplete gamma Q(a, x) = 1 - P(a, x): series for x < a + 1, Lentz's
// continued fraction otherwise.
inline double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double log_prefix = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 100000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::fabs(term) < std::fabs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(log_prefix);
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(log_prefix) * h;
}

// Upper tail probability of a chi-square variable with `dof` degrees of freedom.
inline double chi2_p_value(double chi2, double dof) {
  return gamma_q(0.5 * dof, 0.5 * chi2);
}

// Per-test significance for `tests` tests at overall level `alpha` (Sidak correction).
inline double sidak(double alpha, int tests) {
  return 1.0 - std::pow(1.0 - alpha, 1.0 / tests);
}

}  // namespace gdpt::test
