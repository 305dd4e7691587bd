// SO(3): hat/vee, exp/log at the hard angles, Jacobians against finite differences, the Taylor
// branches against a more precise scalar's closed forms, and nearest_rotation.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>

#include "lie_test_support.hpp"
#include "test_paths.hpp"
#include "ulc/core/lie.hpp"

using lie_test::kPi;
using lie_test::max_diff;
using lie_test::Tol;

TEMPLATE_TEST_CASE("hat and vee are inverse and hat is the cross product", "[lie][so3]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(1);
  for (int i = 0; i < 50; ++i) {
    const ulc::Vec3<S> v = lie_test::random_vector(rng, 3.0).cast<S>();
    const ulc::Vec3<S> w = lie_test::random_vector(rng, 3.0).cast<S>();
    const ulc::Mat3<S> K = ulc::hat(v);
    CHECK(max_diff(K, -K.transpose()) == 0.0);
    CHECK(max_diff(ulc::vee(K), v) == 0.0);
    CHECK(max_diff(K * w, v.cross(w)) < 10 * Tol<S>::exact);
  }
  // vee reads the skew-symmetric part: a symmetric matrix adds nothing.
  const ulc::Vec3<S> v(S(1), S(-2), S(3));
  ulc::Mat3<S> sym;
  sym << 1, 2, 3, 2, 5, 6, 3, 6, 9;
  CHECK(max_diff(ulc::vee(ulc::Mat3<S>(ulc::hat(v) + sym)), v) == 0.0);
}

TEMPLATE_TEST_CASE("so3_exp is a rotation and matches Eigen's AngleAxis", "[lie][so3]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(2);
  const std::vector<double> angles = {0.0, 1e-9, 1e-5, 0.01, 0.3, kPi / 2, 2.5, kPi - 1e-6, kPi};
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d axis = lie_test::random_axis(rng);
    for (const double angle : angles) {
      const ulc::Mat3<S> R = ulc::so3_exp(ulc::Vec3<S>((angle * axis).cast<S>()));
      const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
      CHECK(max_diff(R, expected) < 4 * Tol<S>::exact);
      CHECK(max_diff(R.transpose() * R, ulc::Mat3<S>::Identity()) < 4 * Tol<S>::exact);
      CHECK(std::abs(double(R.determinant()) - 1.0) < 4 * Tol<S>::exact);
    }
  }
}

// Build the exact rotation in double, round it to S, and ask S's log for the angle and axis.
TEMPLATE_TEST_CASE("so3_log recovers the rotation vector at the hard angles", "[lie][so3]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(3);
  const std::vector<double> angles = {0.0, 1e-9,       1e-5,       kPi / 2, 2.0,
                                      3.0, kPi - 1e-6, kPi - 1e-9, kPi};
  // Below this distance from pi the rounded matrix cannot tell the axis from its negative.
  const double sign_blind = std::is_same_v<S, float> ? 1e-7 : 1e-15;
  std::vector<Eigen::Vector3d> axes = {
      Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(),
      Eigen::Vector3d(1, 1, 1).normalized(), Eigen::Vector3d(-1, 0, 1).normalized()};
  for (int i = 0; i < 40; ++i) axes.push_back(lie_test::random_axis(rng));
  for (const auto& axis : axes) {
    for (const double angle : angles) {
      const Eigen::Vector3d phi = angle * axis;
      const ulc::Mat3<S> R = Eigen::AngleAxisd(angle, axis).toRotationMatrix().cast<S>();
      const ulc::Vec3<S> got = ulc::so3_log(R);
      INFO("angle " << angle << " axis " << axis.transpose() << " got " << got.transpose());
      CHECK(std::abs(double(got.norm()) - angle) < Tol<S>::log);
      const double err = max_diff(got, phi);
      if (kPi - angle < sign_blind) {
        CHECK(std::min(err, max_diff(got, -phi)) < Tol<S>::log);
      } else {
        CHECK(err < Tol<S>::log);
      }
    }
  }
}

TEMPLATE_TEST_CASE("exp(log(R)) == R and log(exp(phi)) == phi for |phi| < pi", "[lie][so3]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(4);
  for (int i = 0; i < 500; ++i) {
    const double angle = lie_test::uniform(rng, 0.0, kPi - 1e-3);
    const ulc::Vec3<S> phi = (angle * lie_test::random_axis(rng)).cast<S>();
    const ulc::Mat3<S> R = ulc::so3_exp(phi);
    CHECK(max_diff(ulc::so3_log(R), phi) < Tol<S>::log);
    CHECK(max_diff(ulc::so3_exp(ulc::so3_log(R)), R) < 4 * Tol<S>::exact);
  }
  // Exactly pi about a coordinate axis: a symmetric matrix, either sign is right.
  const ulc::Mat3<S> flip_x = ulc::Vec3<S>(1, -1, -1).asDiagonal();
  const ulc::Vec3<S> log_flip = ulc::so3_log(flip_x);
  CHECK(std::abs(double(std::abs(log_flip.x())) - kPi) < Tol<S>::log);
  CHECK(max_diff(ulc::so3_exp(log_flip), flip_x) < 4 * Tol<S>::exact);
}

namespace {

// Column j of the central difference of perturb(h e_j), perturb returning a tangent vector.
template <typename S, int N, typename F>
Eigen::Matrix<S, N, N> central_difference(F perturb) {
  const S h = S(Tol<S>::fd_step);
  Eigen::Matrix<S, N, N> J;
  for (int j = 0; j < N; ++j) {
    Eigen::Matrix<S, N, 1> d = Eigen::Matrix<S, N, 1>::Zero();
    d(j) = h;
    J.col(j) = (perturb(d) - perturb(Eigen::Matrix<S, N, 1>(-d))) / (S(2) * h);
  }
  return J;
}

template <typename S>
std::vector<ulc::Vec3<S>> jacobian_test_points(std::mt19937& rng) {
  std::vector<ulc::Vec3<S>> points = {
      ulc::Vec3<S>::Zero(), (1e-3 * lie_test::random_axis(rng)).cast<S>(),
      (0.1 * lie_test::random_axis(rng)).cast<S>(), (3.0 * lie_test::random_axis(rng)).cast<S>()};
  for (int i = 0; i < 10; ++i)
    points.push_back((lie_test::uniform(rng, 0.0, 3.0) * lie_test::random_axis(rng)).cast<S>());
  return points;
}

}  // namespace

TEMPLATE_TEST_CASE("SO(3) Jacobians match central finite differences", "[lie][so3]", float,
                   double) {
  using S = TestType;
  using V = ulc::Vec3<S>;
  using M = ulc::Mat3<S>;
  std::mt19937 rng(5);
  for (const V& phi : jacobian_test_points<S>(rng)) {
    INFO("phi " << phi.transpose());
    const M R = ulc::so3_exp(phi);
    // Left: exp(phi + d) ~= exp(J_l d) exp(phi).
    const M left_fd = central_difference<S, 3>(
        [&](const V& d) { return ulc::so3_log(M(ulc::so3_exp(V(phi + d)) * R.transpose())); });
    CHECK(max_diff(ulc::so3_left_jacobian(phi), left_fd) < Tol<S>::fd);
    // Right: exp(phi + d) ~= exp(phi) exp(J_r d).
    const M right_fd = central_difference<S, 3>(
        [&](const V& d) { return ulc::so3_log(M(R.transpose() * ulc::so3_exp(V(phi + d)))); });
    CHECK(max_diff(ulc::so3_right_jacobian(phi), right_fd) < Tol<S>::fd);

    CHECK(max_diff(ulc::so3_left_jacobian(phi) * ulc::so3_left_jacobian_inverse(phi),
                   M::Identity()) < 10 * Tol<S>::exact);
    CHECK(max_diff(ulc::so3_right_jacobian(phi) * ulc::so3_right_jacobian_inverse(phi),
                   M::Identity()) < 10 * Tol<S>::exact);
    // J_l = R J_r: the two perturbation sides differ by the rotation itself.
    CHECK(max_diff(ulc::so3_left_jacobian(phi), R * ulc::so3_right_jacobian(phi)) <
          10 * Tol<S>::exact);
  }
}

// The Taylor branches are only used below a small angle; checking them against the closed forms
// evaluated in a more precise scalar catches a wrong series coefficient that finite differences
// are far too coarse to see.
TEMPLATE_TEST_CASE("SO(3) small-angle series agree with the closed forms of a wider scalar",
                   "[lie][so3]", float, double) {
  using S = TestType;
  using R = typename lie_test::Reference<S>::type;
  ULC_SKIP_UNLESS(std::numeric_limits<R>::digits > std::numeric_limits<S>::digits,
                  "long double is no wider than double on this platform");
  const double thresh_s = std::sqrt(double(ulc::lie_detail::small_angle_sq<S>()));
  const double thresh_r = std::sqrt(double(ulc::lie_detail::small_angle_sq<R>()));
  const double rel = 16 * double(std::numeric_limits<S>::epsilon());
  std::mt19937 rng(6);
  for (const double fraction : {0.4, 0.7, 0.98}) {
    const double angle = fraction * thresh_s;
    REQUIRE(angle > 1.2 * thresh_r);  // S uses its series, R its closed form
    for (int i = 0; i < 5; ++i) {
      const ulc::Vec3<S> phi = (angle * lie_test::random_axis(rng)).cast<S>();
      const ulc::Vec3<R> phi_r = phi.template cast<R>();
      INFO("angle " << angle);
      CHECK(max_diff(ulc::so3_exp(phi), ulc::so3_exp(phi_r)) < rel);
      CHECK(max_diff(ulc::so3_left_jacobian(phi), ulc::so3_left_jacobian(phi_r)) < rel);
      CHECK(max_diff(ulc::so3_right_jacobian(phi), ulc::so3_right_jacobian(phi_r)) < rel);
      CHECK(max_diff(ulc::so3_left_jacobian_inverse(phi), ulc::so3_left_jacobian_inverse(phi_r)) <
            rel);
      const ulc::Mat3<R> rot_r = ulc::so3_exp(phi_r);
      CHECK(max_diff(ulc::so3_log(rot_r.template cast<S>()), ulc::so3_log(rot_r)) < rel);
      // The coefficients themselves, relative (the matrices above scale them by angle^2).
      // The reference's closed forms for c and d cancel to about eps_R / angle^2.
      const double ref_noise = 16 * double(std::numeric_limits<R>::epsilon()) / (angle * angle);
      const auto c_s = ulc::lie_detail::so3_coefficients(phi.squaredNorm());
      const auto c_r = ulc::lie_detail::so3_coefficients(phi_r.squaredNorm());
      CHECK(std::abs(double(c_s.a) - double(c_r.a)) < rel);
      CHECK(std::abs(double(c_s.b) - double(c_r.b)) < rel * 0.5);
      CHECK(std::abs(double(c_s.c) - double(c_r.c)) < rel / 6 + ref_noise);
      const S d_s = ulc::lie_detail::so3_inverse_jacobian_coefficient(phi.squaredNorm());
      const R d_r = ulc::lie_detail::so3_inverse_jacobian_coefficient(phi_r.squaredNorm());
      CHECK(std::abs(double(d_s) - double(d_r)) < rel / 12 + ref_noise);
    }
  }
}

TEMPLATE_TEST_CASE("nearest_rotation is the polar factor and never a reflection", "[lie][so3]",
                   float, double) {
  using S = TestType;
  using M = ulc::Mat3<S>;
  std::mt19937 rng(7);
  for (int i = 0; i < 30; ++i) {
    const Eigen::Matrix3d R = lie_test::random_rotation(rng);
    // M = R P with P symmetric positive definite: the nearest rotation is exactly R.
    const Eigen::Matrix3d Q = lie_test::random_rotation(rng);
    const Eigen::Vector3d s(lie_test::uniform(rng, 0.5, 2.0), lie_test::uniform(rng, 0.5, 2.0),
                            lie_test::uniform(rng, 0.5, 2.0));
    const Eigen::Matrix3d P = Q * s.asDiagonal() * Q.transpose();
    const M got = ulc::nearest_rotation(M((R * P).cast<S>()));
    CHECK(max_diff(got, R) < 20 * Tol<S>::exact);
    CHECK(std::abs(double(got.determinant()) - 1.0) < 10 * Tol<S>::exact);

    // R P with P symmetric but with one small negative eigenvalue has det < 0; its nearest
    // rotation flips that direction back, which gives R again (U V^T alone would reflect).
    const Eigen::Vector3d r(1.0, 0.9, -0.1);
    const M reflected = (R * Q * r.asDiagonal() * Q.transpose()).cast<S>();
    REQUIRE(reflected.determinant() < S(0));
    const M fixed = ulc::nearest_rotation(reflected);
    CHECK(max_diff(fixed, R) < 20 * Tol<S>::exact);
    CHECK(std::abs(double(fixed.determinant()) - 1.0) < 10 * Tol<S>::exact);
  }
}
