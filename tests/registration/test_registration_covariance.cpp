// The covariance of a point-to-plane registration from its final problem
// (ulc/core/registration_covariance.hpp): symmetric positive definite, and with independent
// isotropic point noise it matches the Monte-Carlo spread of the estimate.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "registration_test_util.hpp"
#include "ulc/core/cluster_covariance.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/registration_covariance.hpp"
#include "ulc/core/registration_target.hpp"

using namespace reg_test;
using ulc::Mat6d;

namespace {

/// The courtyard's surfaces without noise (the target) and a noisy sampling of them seen
/// through T_true^-1 (the source): the registration's only error is the source's point noise.
struct Trial {
  Isometry3d estimate;
  Mat6d covariance;
};

Trial register_once(const ulc::PlaneCloud<double>& target, const Isometry3d& T_true,
                    std::uint64_t seed, double sigma) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, sigma);
  std::vector<Vec3d> seen = courtyard(seed + 1000, 150, 0.0);
  for (Vec3d& p : seen) p += Vec3d(gauss(rng), gauss(rng), gauss(rng));
  const std::vector<Vec3d> source = transformed(seen, T_true.inverse());
  ulc::RegistrationOptions o;
  o.max_correspondence_distance = 1.0;
  o.kernel = ulc::RobustKernel::least_squares();
  o.max_iterations = 100;
  const auto r =
      ulc::register_point_to_plane(to_cloud<double>(source), target, Isometry3d::Identity(), o);
  INFO(ulc::to_string(r.status) << ": " << r.reason);
  // Matches of noisy points flip between neighbours from one iteration to the next: the last
  // steps jitter around the minimum by far less than the noise's spread, above the tolerances.
  REQUIRE((r.ok() || r.status == ulc::RegistrationStatus::not_converged));
  const auto cov = ulc::point_to_plane_covariance(source, target, r.pose, o, 0.0);
  REQUIRE(cov);
  return {r.pose, *cov};
}

}  // namespace

TEST_CASE(
    "registration covariance: symmetric positive definite, and it matches the spread "
    "of the estimate under isotropic point noise",
    "[registration][covariance]") {
  const ulc::PlaneCloud<double> target(to_cloud<double>(courtyard(1, 6000, 0.0)));
  std::mt19937_64 rng(3);
  const Isometry3d T_true = random_transform(rng, 3.0 * kDeg, 0.4);
  const double sigma = 0.02;  // m, per axis
  constexpr int kTrials = 150;
  Mat6d spread = Mat6d::Zero(), mean_cov = Mat6d::Zero();
  int inside = 0;
  for (int k = 0; k < kTrials; ++k) {
    const Trial t = register_once(target, T_true, 10 + k, sigma);
    const Mat6d& C = t.covariance;
    CHECK((C - C.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * C.cwiseAbs().maxCoeff());
    REQUIRE(Eigen::SelfAdjointEigenSolver<Mat6d>(C).eigenvalues().minCoeff() > 0.0);
    const Vec6d xi = ulc::se3_log(Isometry3d(T_true * t.estimate.inverse()));
    spread += xi * xi.transpose();
    mean_cov += C;
    inside += xi.dot(C.ldlt().solve(xi)) <= 20.06 ? 1 : 0;  // chi-square(6), 99.73 %
  }
  spread /= kTrials;
  mean_cov /= kTrials;
  // Each standard deviation within 25 % of the Monte-Carlo one (150 trials: the spread's own
  // sampling error is about 6 %), and the whole matrix within 25 % in the covariance's metric.
  for (int i = 0; i < 6; ++i) {
    INFO("axis " << i << ": reported sigma " << std::sqrt(mean_cov(i, i)) << ", Monte-Carlo "
                 << std::sqrt(spread(i, i)));
    CHECK(std::sqrt(mean_cov(i, i)) == Approx(std::sqrt(spread(i, i))).epsilon(0.25));
  }
  const Eigen::LLT<Mat6d> L(mean_cov);
  const Mat6d Linv = L.matrixL().solve(Mat6d::Identity());
  const Mat6d whitened = Linv * spread * Linv.transpose();
  const Eigen::VectorXd l = Eigen::SelfAdjointEigenSolver<Mat6d>(whitened).eigenvalues();
  INFO("eigenvalues of the whitened spread: " << l.transpose());
  CHECK(l.minCoeff() > 0.6);
  CHECK(l.maxCoeff() < 1.6);
  CHECK(inside >= kTrials * 95 / 100);
}

TEST_CASE("cluster covariance: a shared error per cluster widens the sandwich by its size",
          "[registration][covariance]") {
  // The mean of n clusters of m equal observations with one error per cluster: the estimate's
  // variance is sigma^2 / n, which the sandwich over clusters sees and per-point clustering
  // (which believes in n * m independent errors) underestimates m times.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const int n = 400, m = 25;
  std::vector<double> errors;
  for (int c = 0; c < n; ++c) errors.push_back(gauss(rng));
  double mean = 0.0;
  for (double e : errors) mean += e / n;
  ulc::ClusterGradients<1> by_cluster, by_point;
  for (int c = 0; c < n; ++c)
    for (int k = 0; k < m; ++k) {
      const Eigen::Matrix<double, 1, 1> g(errors[c] - mean);  // w J r with J = -1, r = x - mean
      by_cluster.add(c, g);
      by_point.add(c * m + k, g);
    }
  const Eigen::Matrix<double, 1, 1> H(static_cast<double>(n * m));
  const auto clustered = ulc::sandwich_covariance<1>(H, by_cluster.meat());
  const auto independent = ulc::sandwich_covariance<1>(H, by_point.meat());
  REQUIRE(clustered);
  REQUIRE(independent);
  CHECK((*clustered)(0, 0) == Approx(1.0 / n).epsilon(0.15));
  CHECK((*clustered)(0, 0) / (*independent)(0, 0) == Approx(m).epsilon(0.01));
}

TEST_CASE(
    "cluster jackknife: for linear least squares it is the spread of the delete-one-cluster "
    "refits",
    "[registration][covariance]") {
  // y = X b + e with 8 clusters of 5 rows sharing part of their error. For a linear problem the
  // one-step change d_c = (A - A_c)^-1 g_c is the exact change of the estimate when cluster c
  // is left out and the rest refitted, so the jackknife must equal (G - 1) / G times the sum of
  // the refits' outer products (CR3), which is computed here by refitting.
  constexpr int kClusters = 8, kRows = 5;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> gauss(0.0, 1.0);
  using Mat3 = Eigen::Matrix3d;
  using Vec3 = Eigen::Vector3d;
  std::vector<Vec3> x;
  std::vector<double> y;
  std::vector<int> cluster;
  for (int c = 0; c < kClusters; ++c) {
    const double shared = gauss(rng);
    for (int k = 0; k < kRows; ++k) {
      x.emplace_back(1.0, gauss(rng), gauss(rng));
      y.push_back(x.back().dot(Vec3(0.5, -1.0, 2.0)) + shared + 0.3 * gauss(rng));
      cluster.push_back(c);
    }
  }
  const auto fit = [&](int left_out) {
    Mat3 A = Mat3::Zero();
    Vec3 b = Vec3::Zero();
    for (std::size_t i = 0; i < x.size(); ++i)
      if (cluster[i] != left_out) {
        A += x[i] * x[i].transpose();
        b += x[i] * y[i];
      }
    return Vec3(A.ldlt().solve(b));
  };
  const Vec3 all = fit(-1);
  ulc::ClusterJackknife<3> jackknife;
  for (std::size_t i = 0; i < x.size(); ++i)  // r = x . b - y, J = x, w = 1, psi' = 1
    jackknife.add(cluster[i], x[i] * x[i].transpose(), x[i] * (x[i].dot(all) - y[i]));
  Mat3 refits = Mat3::Zero();
  for (int c = 0; c < kClusters; ++c) {
    const Vec3 d = fit(c) - all;
    refits += d * d.transpose();
  }
  refits *= (kClusters - 1.0) / kClusters;
  const auto cov = jackknife.covariance();
  REQUIRE(cov);
  CHECK((*cov - refits).norm() <= 1e-9 * refits.norm());
  // The held problem (the leading two parameters, the third fixed at zero) is the jackknife of
  // that smaller problem's blocks: finite and positive definite.
  const auto held = jackknife.covariance<2>();
  REQUIRE(held);
  CHECK(held->determinant() > 0.0);
  // The jackknife is at least the plain sandwich here: every cluster has leverage.
  ulc::ClusterGradients<3> gradients;
  Mat3 A = Mat3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    gradients.add(cluster[i], x[i] * (x[i].dot(all) - y[i]));
    A += x[i] * x[i].transpose();
  }
  const auto sandwich = ulc::sandwich_covariance<3>(A, gradients.meat());
  REQUIRE(sandwich);
  CHECK(cov->trace() > sandwich->trace());
}
