// SE(3): exp/log against the matrix exponential, the [rho; phi] order and left perturbation
// (the paper's point Jacobian), Jacobians against finite differences, adjoint identities.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "lie_test_support.hpp"
#include "test_paths.hpp"
#include "ulc/core/lie.hpp"

using lie_test::kPi;
using lie_test::max_diff;
using lie_test::Tol;

namespace {

using Mat4d = Eigen::Matrix4d;

// exp of a 4x4 matrix by scaling and squaring of its Taylor series: slow, simple, independent.
Mat4d matrix_exp(const Mat4d& A) {
  int squarings = 0;
  double norm = A.cwiseAbs().rowwise().sum().maxCoeff();
  while (norm > 0.25) {
    norm /= 2;
    ++squarings;
  }
  const Mat4d B = A / std::ldexp(1.0, squarings);
  Mat4d term = Mat4d::Identity(), sum = Mat4d::Identity();
  for (int k = 1; k < 25; ++k) {
    term = term * B / double(k);
    sum += term;
  }
  for (int i = 0; i < squarings; ++i) sum = sum * sum;
  return sum;
}

Eigen::Matrix<double, 6, 1> random_xi(std::mt19937& rng, double angle) {
  Eigen::Matrix<double, 6, 1> xi;
  xi << lie_test::random_vector(rng, 3.0), angle * lie_test::random_axis(rng);
  return xi;
}

template <typename S, typename F>
ulc::Mat6<S> central_difference6(F perturb) {
  const S h = S(Tol<S>::fd_step);
  ulc::Mat6<S> J;
  for (int j = 0; j < 6; ++j) {
    ulc::Vec6<S> d = ulc::Vec6<S>::Zero();
    d(j) = h;
    J.col(j) = (perturb(d) - perturb(ulc::Vec6<S>(-d))) / (S(2) * h);
  }
  return J;
}

}  // namespace

TEMPLATE_TEST_CASE("hat6 and vee6 are inverse", "[lie][se3]", float, double) {
  using S = TestType;
  std::mt19937 rng(11);
  const ulc::Vec6<S> xi = random_xi(rng, 1.0).cast<S>();
  const Eigen::Matrix<S, 4, 4> m = ulc::hat6(xi);
  CHECK(max_diff(ulc::vee6(m), xi) == 0.0);
  CHECK(max_diff(m.row(3), Eigen::Matrix<S, 1, 4>::Zero()) == 0.0);
  CHECK(max_diff(m.template topRightCorner<3, 1>(), xi.template head<3>()) == 0.0);
}

TEMPLATE_TEST_CASE("se3_exp is the matrix exponential of hat6([rho; phi])", "[lie][se3]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(12);
  for (const double angle : {0.0, 1e-9, 1e-4, 0.05, 1.0, 2.5, kPi - 1e-6, kPi}) {
    for (int i = 0; i < 10; ++i) {
      const Eigen::Matrix<double, 6, 1> xi = random_xi(rng, angle);
      const ulc::Isometry3<S> T = ulc::se3_exp(ulc::Vec6<S>(xi.cast<S>()));
      INFO("xi " << xi.transpose());
      CHECK(max_diff(T.matrix(), matrix_exp(ulc::hat6(xi))) < 10 * Tol<S>::exact);
    }
  }
}

TEMPLATE_TEST_CASE("se3 exp/log round trips", "[lie][se3]", float, double) {
  using S = TestType;
  std::mt19937 rng(13);
  // log(exp(xi)) == xi while |phi| < pi, including the small-angle branch.
  std::vector<double> angles = {0.0, 1e-9, 1e-5, 0.1, kPi / 2, 3.0, kPi - 1e-3};
  for (int i = 0; i < 100; ++i) angles.push_back(lie_test::uniform(rng, 0.0, kPi - 1e-3));
  for (const double angle : angles) {
    const ulc::Vec6<S> xi = random_xi(rng, angle).cast<S>();
    INFO("xi " << xi.transpose());
    const ulc::Isometry3<S> T = ulc::se3_exp(xi);
    // The translation part carries |rho| ~ 3 and, near pi, J_l^-1's larger entries.
    CHECK(max_diff(ulc::se3_log(T), xi) < 20 * Tol<S>::log);
    CHECK(max_diff(ulc::se3_exp(ulc::se3_log(T)).matrix(), T.matrix()) < 20 * Tol<S>::exact);
  }
  // exp(log(T)) == T for transforms whose rotation is within rounding of pi.
  for (const double angle : {kPi - 1e-9, kPi}) {
    const Eigen::Vector3d axis = lie_test::random_axis(rng);
    const ulc::Isometry3<S> T = lie_test::make_isometry<S>(
        Eigen::AngleAxisd(angle, axis).toRotationMatrix().cast<S>(), ulc::Vec3<S>(1, -2, 0.5));
    CHECK(max_diff(ulc::se3_exp(ulc::se3_log(T)).matrix(), T.matrix()) < 20 * Tol<S>::exact);
  }
}

TEMPLATE_TEST_CASE("the tangent order is [rho; phi] with left perturbation: J_p = [I, -[Tp]x]",
                   "[lie][se3]", float, double) {
  using S = TestType;
  using V6 = ulc::Vec6<S>;
  std::mt19937 rng(14);
  const ulc::Isometry3<S> T = lie_test::random_isometry<S>(rng);
  const ulc::Vec3<S> p(S(1.5), S(-0.5), S(2));
  const ulc::Vec3<S> Tp = T * p;
  Eigen::Matrix<S, 3, 6> expected;
  expected << ulc::Mat3<S>::Identity(), -ulc::hat(Tp);
  const S h = S(Tol<S>::fd_step);
  Eigen::Matrix<S, 3, 6> fd;
  for (int j = 0; j < 6; ++j) {
    V6 d = V6::Zero();
    d(j) = h;
    fd.col(j) = ((ulc::se3_exp(d) * T) * p - (ulc::se3_exp(V6(-d)) * T) * p) / (S(2) * h);
  }
  CHECK(max_diff(fd, expected) < Tol<S>::fd);
}

TEMPLATE_TEST_CASE("SE(3) Jacobians match central finite differences", "[lie][se3]", float,
                   double) {
  using S = TestType;
  using V6 = ulc::Vec6<S>;
  using M6 = ulc::Mat6<S>;
  std::mt19937 rng(15);
  std::vector<V6> points = {V6::Zero(), random_xi(rng, 0.0).cast<S>(),
                            random_xi(rng, 1e-3).cast<S>(), random_xi(rng, 0.1).cast<S>(),
                            random_xi(rng, 3.0).cast<S>()};
  for (int i = 0; i < 8; ++i)
    points.push_back(random_xi(rng, lie_test::uniform(rng, 0.0, 3.0)).cast<S>());
  for (const V6& xi : points) {
    INFO("xi " << xi.transpose());
    const ulc::Isometry3<S> T = ulc::se3_exp(xi);
    const ulc::Isometry3<S> T_inv = T.inverse();
    // Left: exp(xi + d) ~= exp(J_l d) exp(xi).
    const M6 left_fd = central_difference6<S>([&](const V6& d) {
      return ulc::se3_log(ulc::Isometry3<S>(ulc::se3_exp(V6(xi + d)) * T_inv));
    });
    // Right: exp(xi + d) ~= exp(xi) exp(J_r d).
    const M6 right_fd = central_difference6<S>([&](const V6& d) {
      return ulc::se3_log(ulc::Isometry3<S>(T_inv * ulc::se3_exp(V6(xi + d))));
    });
    // Entries grow with |rho| ~ 3, so scale the finite-difference tolerance.
    CHECK(max_diff(ulc::se3_left_jacobian(xi), left_fd) < 5 * Tol<S>::fd);
    CHECK(max_diff(ulc::se3_right_jacobian(xi), right_fd) < 5 * Tol<S>::fd);

    CHECK(max_diff(ulc::se3_left_jacobian(xi) * ulc::se3_left_jacobian_inverse(xi),
                   M6::Identity()) < 50 * Tol<S>::exact);
    CHECK(max_diff(ulc::se3_right_jacobian(xi) * ulc::se3_right_jacobian_inverse(xi),
                   M6::Identity()) < 50 * Tol<S>::exact);
    // J_l = Ad(exp(xi)) J_r.
    CHECK(max_diff(ulc::se3_left_jacobian(xi), ulc::adjoint(T) * ulc::se3_right_jacobian(xi)) <
          50 * Tol<S>::exact);
  }
}

TEMPLATE_TEST_CASE("SE(3) small-angle series agree with the closed forms of a wider scalar",
                   "[lie][se3]", float, double) {
  using S = TestType;
  using R = typename lie_test::Reference<S>::type;
  ULC_SKIP_UNLESS(std::numeric_limits<R>::digits > std::numeric_limits<S>::digits,
                  "long double is no wider than double on this platform");
  const double thresh_s = std::sqrt(double(ulc::lie_detail::small_angle_sq<S>()));
  const double thresh_r = std::sqrt(double(ulc::lie_detail::small_angle_sq<R>()));
  const double tol = 64 * double(std::numeric_limits<S>::epsilon());  // entries up to ~|rho|
  std::mt19937 rng(16);
  for (const double fraction : {0.4, 0.7, 0.98}) {
    const double angle = fraction * thresh_s;
    REQUIRE(angle > 1.2 * thresh_r);
    for (int i = 0; i < 5; ++i) {
      const ulc::Vec6<S> xi = random_xi(rng, angle).cast<S>();
      const ulc::Vec6<R> xi_r = xi.template cast<R>();
      INFO("angle " << angle);
      CHECK(max_diff(ulc::se3_exp(xi).matrix(), ulc::se3_exp(xi_r).matrix()) < tol);
      CHECK(max_diff(ulc::se3_left_jacobian(xi), ulc::se3_left_jacobian(xi_r)) < tol);
      CHECK(max_diff(ulc::se3_left_jacobian_inverse(xi), ulc::se3_left_jacobian_inverse(xi_r)) <
            tol);
      // The Q block alone, relative to its size: its series terms are scaled by angle^2.
      const ulc::Vec3<S> rho = xi.template head<3>(), phi = xi.template tail<3>();
      const ulc::Mat3<R> q_r =
          ulc::lie_detail::se3_q_block<R>(rho.template cast<R>(), phi.template cast<R>());
      const ulc::Mat3<R> q_r_linear = ulc::hat(rho.template cast<R>()) / R(2);
      const ulc::Mat3<S> q_s = ulc::lie_detail::se3_q_block<S>(rho, phi);
      const double higher = double((q_r - q_r_linear).cwiseAbs().maxCoeff());
      CHECK(max_diff(q_s - ulc::hat(rho) / S(2), q_r - q_r_linear) < tol * higher + tol / 8);
    }
  }
}

TEMPLATE_TEST_CASE("adjoint moves a tangent vector through a transform", "[lie][se3]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(17);
  for (int i = 0; i < 20; ++i) {
    const ulc::Isometry3<S> T = lie_test::random_isometry<S>(rng);
    const ulc::Isometry3<S> U = lie_test::random_isometry<S>(rng);
    const ulc::Vec6<S> xi = random_xi(rng, lie_test::uniform(rng, 0.0, 2.0)).cast<S>();
    // exp(Ad_T xi) = T exp(xi) T^-1
    CHECK(max_diff(ulc::se3_exp(ulc::Vec6<S>(ulc::adjoint(T) * xi)).matrix(),
                   (T * ulc::se3_exp(xi) * T.inverse()).matrix()) < 50 * Tol<S>::exact);
    // A homomorphism: Ad(T U) = Ad(T) Ad(U), Ad(T^-1) = Ad(T)^-1.
    CHECK(max_diff(ulc::adjoint(ulc::Isometry3<S>(T * U)), ulc::adjoint(T) * ulc::adjoint(U)) <
          20 * Tol<S>::exact);
    CHECK(max_diff(ulc::adjoint(ulc::Isometry3<S>(T.inverse())) * ulc::adjoint(T),
                   ulc::Mat6<S>::Identity()) < 20 * Tol<S>::exact);
  }
}
