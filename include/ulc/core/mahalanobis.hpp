// The squared Mahalanobis distance of a 6-vector error to a covariance, and the 3-sigma
// ellipsoid test on it: how bench_covariance judges a reported covariance against the truth and
// how HOTS judges whether its start lies within its answer's uncertainty
// (hots/refine_steps.hpp, rerun_from_start).
#pragma once

#include <optional>

#include <Eigen/Cholesky>

#include "ulc/core/small_sample.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// d^2 = xi^T Sigma^-1 xi; nullopt when Sigma is not positive definite.
inline std::optional<double> mahalanobis_sq(const Vec6d& xi, const Mat6d& sigma) {
  const Eigen::LDLT<Mat6d> ldlt(sigma);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return std::nullopt;
  return xi.dot(ldlt.solve(xi));
}

/// Whether xi lies within the ellipsoid of Sigma holding kThreeSigmaLevel of a 6-d Gaussian;
/// false when Sigma is not positive definite (it vouches for nothing).
inline bool within_three_sigma(const Vec6d& xi, const Mat6d& sigma) {
  const std::optional<double> d2 = mahalanobis_sq(xi, sigma);
  return d2 && *d2 <= chi_square_quantile(kThreeSigmaLevel, 6);
}

}  // namespace ulc
