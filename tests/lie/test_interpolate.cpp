// Interpolation and extrapolation of rotations and transforms.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "lie_test_support.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"

using lie_test::max_diff;
using lie_test::Tol;

TEMPLATE_TEST_CASE("interpolate hits its ends and halves the angle at 0.5", "[lie][interp]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(21);
  for (int i = 0; i < 30; ++i) {
    const ulc::Isometry3<S> T0 = lie_test::random_isometry<S>(rng);
    const ulc::Isometry3<S> T1 = lie_test::random_isometry<S>(rng);
    CHECK(max_diff(ulc::interpolate(T0, T1, 0.0).matrix(), T0.matrix()) < 10 * Tol<S>::exact);
    CHECK(max_diff(ulc::interpolate(T0, T1, 1.0).matrix(), T1.matrix()) < 10 * Tol<S>::exact);

    const ulc::Isometry3<S> mid = ulc::interpolate(T0, T1, 0.5);
    const double whole = ulc::rotation_error_rad(T0.linear(), T1.linear());
    const double first = ulc::rotation_error_rad(T0.linear(), mid.linear());
    const double second = ulc::rotation_error_rad(mid.linear(), T1.linear());
    INFO("whole angle " << whole);
    CHECK(std::abs(first - second) < 10 * Tol<S>::log);
    CHECK(std::abs(first - whole / 2) < 10 * Tol<S>::log);
    CHECK(max_diff(mid.translation(), (T0.translation() + T1.translation()) / S(2)) <
          10 * Tol<S>::exact);
    // A rotation, not just a matrix.
    CHECK(max_diff(mid.linear().transpose() * mid.linear(), ulc::Mat3<S>::Identity()) <
          10 * Tol<S>::exact);
  }
}

TEMPLATE_TEST_CASE("interpolate extrapolates a constant motion beyond [0, 1]", "[lie][interp]",
                   float, double) {
  using S = TestType;
  std::mt19937 rng(22);
  for (int i = 0; i < 20; ++i) {
    // Constant angular velocity w and linear velocity v: R(a) = R0 exp(a w), t(a) = t0 + a v.
    const ulc::Mat3<S> R0 = lie_test::random_rotation(rng).cast<S>();
    const ulc::Vec3<S> t0 = lie_test::random_vector(rng, 2.0).cast<S>();
    const ulc::Vec3<S> w = (0.8 * lie_test::random_axis(rng)).cast<S>();
    const ulc::Vec3<S> v = lie_test::random_vector(rng, 1.0).cast<S>();
    const auto at = [&](S a) {
      return lie_test::make_isometry<S>(R0 * ulc::so3_exp(ulc::Vec3<S>(a * w)),
                                        ulc::Vec3<S>(t0 + a * v));
    };
    const ulc::Isometry3<S> T0 = at(S(0)), T1 = at(S(1));
    for (const S a : {S(-0.5), S(0.25), S(1.5), S(2)}) {
      INFO("alpha " << a);
      CHECK(max_diff(ulc::interpolate(T0, T1, a).matrix(), at(a).matrix()) < 10 * Tol<S>::log);
    }
  }
}

TEMPLATE_TEST_CASE("quaternion slerp matches Eigen's and ignores the quaternion sign",
                   "[lie][interp]", float, double) {
  using S = TestType;
  using Q = Eigen::Quaternion<S>;
  std::mt19937 rng(23);
  for (int i = 0; i < 20; ++i) {
    const Q q0(lie_test::random_rotation(rng).cast<S>());
    const Q q1(lie_test::random_rotation(rng).cast<S>());
    for (const S a : {S(0), S(0.3), S(0.5), S(1)}) {
      const Q ours = ulc::slerp(q0, q1, a);
      const Q theirs = q0.slerp(a, q1);
      // q and -q are the same rotation: compare matrices.
      CHECK(max_diff(ours.toRotationMatrix(), theirs.toRotationMatrix()) < 10 * Tol<S>::log);
      const Q flipped(-q1.w(), -q1.x(), -q1.y(), -q1.z());
      CHECK(max_diff(ulc::slerp(q0, flipped, a).toRotationMatrix(), ours.toRotationMatrix()) <
            10 * Tol<S>::exact);
    }
  }
}
