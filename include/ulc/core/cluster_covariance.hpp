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
// With few clusters (a 10 s drive has about 25 target frames for 6-7 parameters) the sandwich
// is too small: each cluster's gradient is measured at an estimate it helped to fit (a leverage
// of about N / G each). The delete-one-cluster jackknife (CR3, Cameron and Miller section VI.B;
// MacKinnon and White 1985) removes that: with A = sum of every residual's curvature and A_c
// the share of cluster c,
//   cov(x) = (G - 1) / G * sum_c d_c d_c^T,   d_c = (A - A_c)^-1 g_c,
// d_c being the one-step change of the estimate when cluster c is left out
// (ClusterJackknife; measured in docs/experiments/covariance_coverage.md). An estimate from G
// clusters is itself uncertain: the ellipsoids it draws hold their probability only once
// widened by Hotelling's T^2 against chi-square (widened_covariance, ulc/core/small_sample.hpp).
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
#include <utility>

#include <Eigen/Core>
#include <Eigen/LU>

#include "ulc/core/small_sample.hpp"
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

/// Per-cluster curvature and gradient sums for the delete-one-cluster jackknife (CR3, see the
/// top). add(key, a, g) takes one residual's curvature a = psi'(r) J J^T and gradient
/// g = w r J; clusters are kept in key order (std::map), so sums do not depend on threads when
/// the caller adds sequentially.
template <int N, class Key = std::int64_t>
class ClusterJackknife {
 public:
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;

  void add(const Key& key, const Mat& curvature, const Vec& gradient) {
    auto [it, fresh] = sums_.try_emplace(key, curvature, gradient);
    if (!fresh) {
      it->second.first += curvature;
      it->second.second += gradient;
    }
  }
  std::size_t clusters() const { return sums_.size(); }

  /// The jackknife covariance of the leading M parameters (M <= N: the problem with the last
  /// N - M parameters held); nullopt with fewer than two clusters, or when leaving one cluster
  /// out makes the problem singular (that cluster alone pins a direction), or a non-finite result.
  template <int M = N>
  std::optional<Eigen::Matrix<double, M, M>> covariance() const {
    using SubMat = Eigen::Matrix<double, M, M>;
    const double G = static_cast<double>(sums_.size());
    if (G < 2.0) return std::nullopt;
    SubMat A = SubMat::Zero();
    for (const auto& kv : sums_) A += kv.second.first.template topLeftCorner<M, M>();
    SubMat cov = SubMat::Zero();
    for (const auto& kv : sums_) {
      const Eigen::FullPivLU<SubMat> lu(SubMat(A - kv.second.first.template topLeftCorner<M, M>()));
      if (!lu.isInvertible()) return std::nullopt;
      const Eigen::Matrix<double, M, 1> d = lu.solve(kv.second.second.template head<M>());
      cov.noalias() += d * d.transpose();
    }
    cov = ((G - 1.0) / G * 0.5 * (cov + cov.transpose())).eval();
    if (!cov.allFinite()) return std::nullopt;
    return cov;
  }

  /// The leading M x M block of covariance<P>() (the marginal of M parameters of the problem in
  /// the leading P, the rest held), widened for its few clusters by small_sample_scale(M, G)
  /// (ulc/core/small_sample.hpp: Hotelling's T^2 against chi-square at the 3-sigma level), so
  /// that its 3-sigma ellipsoid keeps its probability; the covariance a result reports. nullopt
  /// also when G - 1 < M (too few clusters to estimate M directions).
  template <int M, int P = M>
  std::optional<Eigen::Matrix<double, M, M>> widened_marginal() const {
    static_assert(M <= P && P <= N, "a marginal of the leading P <= N parameters");
    const std::optional<double> k = small_sample_scale(M, static_cast<double>(sums_.size()));
    if (!k) return std::nullopt;
    const auto cov = covariance<P>();
    if (!cov) return std::nullopt;
    return Eigen::Matrix<double, M, M>(*k * cov->template topLeftCorner<M, M>());
  }

  /// covariance<M>() widened for its few clusters (widened_marginal with nothing marginalised).
  template <int M = N>
  std::optional<Eigen::Matrix<double, M, M>> widened_covariance() const {
    return widened_marginal<M, M>();
  }

 private:
  std::map<Key, std::pair<Mat, Vec>> sums_;
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
