// How much wider a covariance estimated from few clusters must be for its ellipsoids to keep
// their probability.
//
// A covariance S estimated from G independent clusters (a jackknife or a sandwich over G frames)
// carries about nu = G - 1 degrees of freedom. For an error x ~ N(0, Sigma) independent of S,
// d^2 = x^T S^-1 x does not follow chi-square(p) but Hotelling's T^2(p, nu):
//   T^2(p, nu) = p nu / (nu - p + 1) F(p, nu - p + 1),
// whose quantiles lie far beyond chi-square's when nu is small (p = 6, G = 25: 39.0 against
// 20.06 at 99.73 %, 1.39 in sigma). Reporting k S with
//   k = q_T2(level; p, nu) / q_chi2(level; p)
// makes the chi-square ellipsoid of the reported covariance, the one a user draws, hold the
// stated probability `level` (the 3-sigma level, 99.73 %, by default). It tends to 1 as G grows.
//
// The distributions are computed here with no library: chi-square's CDF is the regularised lower
// incomplete gamma P(p/2, x/2) (its series), F's is the regularised incomplete beta
// I_z(d1/2, d2/2), z = d1 f / (d1 f + d2) (Lentz's continued fraction), and quantiles are found
// by bisection; accurate to about 1e-10 relative, far beyond what a scale factor needs.
// Nothing here throws.
#pragma once

#include <cmath>
#include <limits>
#include <optional>

namespace ulc {
namespace small_sample_detail {

/// P(a, x), the regularised lower incomplete gamma function, by its power series (converges
/// for every x >= 0; the terms shrink once n > x).
inline double lower_gamma_regularised(double a, double x) {
  if (!(x > 0.0)) return 0.0;
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 100000 && term > sum * 1e-16; ++n) {
    term *= x / (a + n);
    sum += term;
  }
  return std::fmin(1.0, sum * std::exp(-x + a * std::log(x) - std::lgamma(a)));
}

/// The continued fraction of I_x(a, b) (modified Lentz), valid for x < (a + 1) / (a + b + 2).
inline double beta_fraction(double a, double b, double x) {
  constexpr double tiny = 1e-300;
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  d = 1.0 / (std::fabs(d) < tiny ? tiny : d);
  double f = d;
  for (int m = 1; m < 10000; ++m) {
    const double m2 = 2.0 * m;
    for (const double num : {m * (b - m) * x / ((a + m2 - 1.0) * (a + m2)),
                             -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0))}) {
      d = 1.0 + num * d;
      d = 1.0 / (std::fabs(d) < tiny ? tiny : d);
      c = 1.0 + num / c;
      if (std::fabs(c) < tiny) c = tiny;
      f *= c * d;
    }
    if (std::fabs(c * d - 1.0) < 1e-15) break;
  }
  return f;
}

/// I_x(a, b), the regularised incomplete beta function.
inline double beta_regularised(double a, double b, double x) {
  if (!(x > 0.0)) return 0.0;
  if (!(x < 1.0)) return 1.0;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_fraction(a, b, x) / a;
  return 1.0 - front * beta_fraction(b, a, 1.0 - x) / b;
}

/// The x at which an increasing CDF reaches p, by doubling a bracket then bisecting.
template <class Cdf>
double quantile_by_bisection(const Cdf& cdf, double p) {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 2000 && cdf(hi) < p; ++i) {
    lo = hi;
    hi *= 2.0;
  }
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (cdf(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace small_sample_detail

/// P(X <= x) for X ~ chi-square with k degrees of freedom.
inline double chi_square_cdf(double x, double k) {
  return small_sample_detail::lower_gamma_regularised(0.5 * k, 0.5 * x);
}

/// P(X <= f) for X ~ F(d1, d2).
inline double f_cdf(double f, double d1, double d2) {
  if (!(f > 0.0)) return 0.0;
  return small_sample_detail::beta_regularised(0.5 * d1, 0.5 * d2, d1 * f / (d1 * f + d2));
}

inline double chi_square_quantile(double p, double k) {
  return small_sample_detail::quantile_by_bisection([k](double x) { return chi_square_cdf(x, k); },
                                                    p);
}

inline double f_quantile(double p, double d1, double d2) {
  return small_sample_detail::quantile_by_bisection([d1, d2](double f) { return f_cdf(f, d1, d2); },
                                                    p);
}

/// The probability of |x| <= 3 sigma in one dimension, the level ULC's covariances are scaled
/// for (docs/BENCHMARKS.md, bench_covariance).
inline constexpr double kThreeSigmaLevel = 0.9973;

/// k = q_T2(level; p, G - 1) / q_chi2(level; p) (see the top): the factor that widens a
/// p-dimensional covariance estimated from G clusters; nullopt when G - 1 < p (T^2 undefined:
/// too few clusters to estimate p directions) or p < 1.
inline std::optional<double> small_sample_scale(int p, double clusters,
                                                double level = kThreeSigmaLevel) {
  const double nu = clusters - 1.0;
  if (p < 1 || !(nu >= p) || !(level > 0.0 && level < 1.0)) return std::nullopt;
  if (nu > 1e7) return 1.0;  // T^2 and chi-square agree to 1e-6 and the CDFs lose precision
  const double d2 = nu - p + 1.0;
  const double t2 = p * nu / d2 * f_quantile(level, p, d2);
  return t2 / chi_square_quantile(level, p);
}

}  // namespace ulc
