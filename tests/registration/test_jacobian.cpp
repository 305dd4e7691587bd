// The point-to-plane Jacobians against central finite differences of the residual: the
// paper's single-scan Jacobian n^T [I, -[Tp]x] and the pose phase's joint Jacobian, where a
// target LiDAR point reaches its map through C^-1 exp(d) T C (eq:je_odom).
#include <catch2/catch.hpp>
#include <random>

#include "registration_test_util.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_to_plane.hpp"

using namespace reg_test;

namespace {

/// r(d) = n . (post * exp(d) * T * pre * x - p), the residual as the optimiser perturbs T.
double residual_at(const Isometry3d& pre, const Isometry3d& T, const Isometry3d& post,
                   const Vec3d& x, const ulc::PlaneMatch& plane, const Vec6d& d) {
  const ulc::PointToPlaneGeometry g(pre, ulc::se3_exp(d) * T, post);
  const Vec3d y = g.pose_frame(x);
  return g.residual(y, g.target_frame(y), plane, nullptr);
}

Vec6d central_difference(const Isometry3d& pre, const Isometry3d& T, const Isometry3d& post,
                         const Vec3d& x, const ulc::PlaneMatch& plane) {
  const double h = 1e-6;
  Vec6d J;
  for (int i = 0; i < 6; ++i) {
    Vec6d d = Vec6d::Zero();
    d[i] = h;
    J[i] = (residual_at(pre, T, post, x, plane, d) - residual_at(pre, T, post, x, plane, -d)) /
           (2 * h);
  }
  return J;
}

Vec6d analytic(const Isometry3d& pre, const Isometry3d& T, const Isometry3d& post, const Vec3d& x,
               const ulc::PlaneMatch& plane) {
  const ulc::PointToPlaneGeometry g(pre, T, post);
  const Vec3d y = g.pose_frame(x);
  Vec6d J;
  g.residual(y, g.target_frame(y), plane, &J);
  return J;
}

ulc::PlaneMatch random_plane(std::mt19937_64& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  ulc::PlaneMatch plane;
  plane.point = Vec3d(gauss(rng), gauss(rng), gauss(rng)) * 10.0;
  plane.normal = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  return plane;
}

}  // namespace

TEST_CASE("single-scan Jacobian matches central differences and the paper's form",
          "[registration][jacobian]") {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const Isometry3d T = random_transform(rng, 0.5 + trial * 0.05, 20.0);
    const Vec3d x = Vec3d(gauss(rng), gauss(rng), gauss(rng)) * 15.0;
    const ulc::PlaneMatch plane = random_plane(rng);
    const Isometry3d I = Isometry3d::Identity();
    const Vec6d J = analytic(I, T, I, x, plane);
    const Vec6d J_fd = central_difference(I, T, I, x, plane);
    INFO("trial " << trial << "\nJ    " << J.transpose() << "\nJ_fd " << J_fd.transpose());
    CHECK((J - J_fd).norm() < 1e-6 * (1.0 + J.norm()));
    // The paper: n^T [I, -[Tp]x].
    Eigen::Matrix<double, 3, 6> Jp;
    Jp.leftCols<3>() = ulc::Mat3d::Identity();
    Jp.rightCols<3>() = -ulc::hat(Vec3d(T * x));
    const Vec6d paper = (plane.normal.transpose() * Jp).transpose();
    CHECK((J - paper).norm() < 1e-12 * (1.0 + J.norm()));
  }
}

TEST_CASE("joint Jacobian of a target point through C^-1 exp(d) T C matches central differences",
          "[registration][jacobian][jeep]") {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const Isometry3d C = random_transform(rng, 0.3 + trial * 0.05, 2.0);
    const Isometry3d T = random_transform(rng, 0.2 + trial * 0.03, 15.0);
    // pre may also carry the base LiDAR's motion over the pairing gap: C -> M C.
    const Isometry3d M = trial % 2 ? random_transform(rng, 0.01, 0.3) : Isometry3d::Identity();
    const Vec3d x = Vec3d(gauss(rng), gauss(rng), gauss(rng)) * 15.0;
    const ulc::PlaneMatch plane = random_plane(rng);
    const Isometry3d pre = M * C, post = C.inverse();
    const Vec6d J = analytic(pre, T, post, x, plane);
    const Vec6d J_fd = central_difference(pre, T, post, x, plane);
    INFO("trial " << trial << "\nJ    " << J.transpose() << "\nJ_fd " << J_fd.transpose());
    CHECK((J - J_fd).norm() < 1e-6 * (1.0 + J.norm()));
    // The paper's form (M = I): n^T R_{C^-1} [I, -[R_T R_C p + R_T t_C + t_T]x].
    if (trial % 2 == 0) {
      const Vec3d y = T.linear() * C.linear() * x + T.linear() * C.translation() + T.translation();
      Eigen::Matrix<double, 3, 6> Jp;
      Jp.leftCols<3>() = ulc::Mat3d::Identity();
      Jp.rightCols<3>() = -ulc::hat(y);
      const Vec6d paper = (plane.normal.transpose() * C.inverse().linear() * Jp).transpose();
      CHECK((J - paper).norm() < 1e-12 * (1.0 + J.norm()));
    }
  }
}

TEST_CASE("the summed normal equations are those of the residuals", "[registration][jacobian]") {
  // A target that answers every query with one fixed plane: the sums can be checked by hand.
  struct OnePlane {
    ulc::PlaneMatch plane;
    bool find_plane(const Vec3d&, double, ulc::PlaneMatch& out) const {
      out = plane;
      return true;
    }
  };
  std::mt19937_64 rng(4);
  OnePlane target{random_plane(rng)};
  std::vector<Vec3d> points = courtyard(5, 200, 0.0);
  const Isometry3d T = random_transform(rng, 0.3, 3.0);
  const Isometry3d C = random_transform(rng, 0.4, 1.0);
  std::vector<ulc::PointToPlaneTerm<double, OnePlane>> terms(2);
  terms[0] = {points.data(),          points.size(),          &target,
              Isometry3d::Identity(), Isometry3d::Identity(), 1.0};
  terms[1] = {points.data(), points.size(), &target, C, C.inverse(), 0.5};
  ulc::RegistrationOptions o;
  o.kernel = ulc::RobustKernel::huber(0.5);
  const auto sums = ulc::sum_point_to_plane(terms, T, o);
  ulc::Mat6d H = ulc::Mat6d::Zero();
  Vec6d b = Vec6d::Zero();
  for (const auto& term : terms) {
    for (const Vec3d& x : points) {
      const Vec6d J = central_difference(term.pre, T, term.post, x, target.plane);
      const double r = residual_at(term.pre, T, term.post, x, target.plane, Vec6d::Zero());
      const double w = term.weight * o.kernel.weight(r);
      H += w * J * J.transpose();
      b += w * r * J;
    }
  }
  CHECK(sums.equations.count == 2 * points.size());
  CHECK((sums.equations.H - H).norm() < 1e-6 * H.norm());
  CHECK((sums.equations.b - b).norm() < 1e-6 * b.norm());
}
