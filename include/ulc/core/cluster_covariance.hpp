// The covariance of a robust least-squares estimate from its final problem: the cluster-robust
// ("sandwich") estimator of Liang and Zeger (1986), as econometrics uses it for correlated
// residuals (Cameron and Miller, "A Practitioner's Guide to Cluster-Robust Inference", 2015).
//
// At the estimate x of F(x) = 1/2 sum_i w_i r_i^2, with H = sum w J J^T (Gauss-Newton):
//   cov(x) = H^-1 M H^-1,   M = G / (G - 1) * sum_c g_c g_c^T,   g_c = sum_{i in c} w_i J_i r_i,
// over G clusters c of residuals that may share their errors, clusters independent of one
// another. G / (G - 1) is the usual small-sample correction (CR1). With one residual per cluster
// this is the heteroscedasticity-robust sandwich; with independent, equal noise sigma^2 it tends
// to the textbook sigma^2 H^-1. Residuals that share an error (the points of one frame with one
// pose error, the points of one wall with one modelling error) put their gradients in one
// cluster; treating them as independent would be optimistic by the square root of the cluster
// size.
//
// Conventions this header owns:
//   - N parameters (6 for an extrinsic [rho; phi], 7 with a clock offset); H symmetric.
//   - ClusterGradients sums per-residual gradients by an integer key, in key order (a std::map):
//     the same sums for the same residuals in any insertion order of equal keys' terms summed
//     in the same order, so results do not depend on threads when the caller adds sequentially.
//   - Nothing here throws; no covariance (std::nullopt) when H is not invertible or there are
//     fewer than two clusters.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <optional>

#include <Eigen/Core>
#include <Eigen/LU>

#include "ulc/core/types.hpp"

namespace ulc {

template <int N, class Key = std::int64_t>
class ClusterGradients {
 public:
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;

  void add(const Key& key, const Vec& g) {
    auto [it, fresh] = sums_.try_emplace(key, g);
    if (!fresh) it->second += g;
  }
  std::size_t clusters() const { return sums_.size(); }

  /// G / (G - 1) * sum_c g_c g_c^T (zero with fewer than two clusters).
  Mat meat() const {
    Mat M = Mat::Zero();
    const double G = static_cast<double>(sums_.size());
    if (G < 2.0) return M;
    for (const auto& kv : sums_) M.noalias() += kv.second * kv.second.transpose();
    return M * (G / (G - 1.0));
  }

 private:
  std::map<Key, Vec> sums_;
};

/// H^-1 M H^-1, symmetrised; nullopt when H is not invertible or the result is not finite.
template <int N>
std::optional<Eigen::Matrix<double, N, N>> sandwich_covariance(
    const Eigen::Matrix<double, N, N>& H, const Eigen::Matrix<double, N, N>& meat) {
  using Mat = Eigen::Matrix<double, N, N>;
  const Eigen::FullPivLU<Mat> lu(H);
  if (!lu.isInvertible()) return std::nullopt;
  const Mat Hinv = lu.inverse();
  Mat cov = Hinv * meat * Hinv.transpose();
  cov = (0.5 * (cov + cov.transpose())).eval();
  if (!cov.allFinite()) return std::nullopt;
  return cov;
}

/// A key for the cubic cell of side `size` that holds p (21 bits per axis: +-1e6 cells).
inline std::int64_t cell_key(const Vec3d& p, double size) {
  constexpr std::int64_t kHalf = std::int64_t{1} << 20, kMask = (std::int64_t{1} << 21) - 1;
  std::int64_t key = 0;
  for (int i = 0; i < 3; ++i) {
    const double c = std::floor(p[i] / size);
    const std::int64_t k =
        std::isfinite(c)
            ? static_cast<std::int64_t>(std::fmax(-double(kHalf), std::fmin(c, kHalf - 1)))
            : 0;
    key = (key << 21) | ((k + kHalf) & kMask);
  }
  return key;
}

}  // namespace ulc
