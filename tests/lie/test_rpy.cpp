// Roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll), radians.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "lie_test_support.hpp"
#include "ulc/core/lie.hpp"

using lie_test::kPi;
using lie_test::max_diff;
using lie_test::Tol;

TEMPLATE_TEST_CASE("rotation_from_rpy: known axes and the z-y-x order", "[lie][rpy]", float,
                   double) {
  using S = TestType;
  using V = ulc::Vec3<S>;
  const S half_pi = S(kPi / 2);
  // Yaw 90 deg maps x to y; pitch 90 deg maps x to -z; roll 90 deg maps y to z.
  CHECK(max_diff(ulc::rotation_from_rpy(S(0), S(0), half_pi) * V::UnitX(), V::UnitY()) <
        Tol<S>::exact);
  CHECK(max_diff(ulc::rotation_from_rpy(S(0), half_pi, S(0)) * V::UnitX(), V(-V::UnitZ())) <
        Tol<S>::exact);
  CHECK(max_diff(ulc::rotation_from_rpy(half_pi, S(0), S(0)) * V::UnitY(), V::UnitZ()) <
        Tol<S>::exact);
  // Roll first (about x), then pitch (about y), then yaw (about z), all about fixed axes.
  std::mt19937 rng(31);
  for (int i = 0; i < 20; ++i) {
    const double r = lie_test::uniform(rng, -kPi, kPi), p = lie_test::uniform(rng, -1.5, 1.5),
                 y = lie_test::uniform(rng, -kPi, kPi);
    const Eigen::Matrix3d expected = (Eigen::AngleAxisd(y, Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(p, Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()))
                                         .toRotationMatrix();
    CHECK(max_diff(ulc::rotation_from_rpy(S(r), S(p), S(y)), expected) < 4 * Tol<S>::exact);
  }
}

TEMPLATE_TEST_CASE("rpy_from_rotation inverts rotation_from_rpy", "[lie][rpy]", float, double) {
  using S = TestType;
  std::mt19937 rng(32);
  for (int i = 0; i < 200; ++i) {
    const ulc::Vec3<S> rpy(S(lie_test::uniform(rng, -3.1, 3.1)),
                           S(lie_test::uniform(rng, -1.55, 1.55)),
                           S(lie_test::uniform(rng, -3.1, 3.1)));
    const ulc::Vec3<S> got =
        ulc::rpy_from_rotation(ulc::rotation_from_rpy(rpy.x(), rpy.y(), rpy.z()));
    INFO("rpy " << rpy.transpose() << " got " << got.transpose());
    CHECK(max_diff(got, rpy) < 50 * Tol<S>::log);
  }
}

TEMPLATE_TEST_CASE("rpy_from_rotation at and near gimbal lock", "[lie][rpy]", float, double) {
  using S = TestType;
  std::mt19937 rng(33);
  for (const double pitch : {kPi / 2, -kPi / 2}) {
    for (int i = 0; i < 20; ++i) {
      const double r = lie_test::uniform(rng, -3.0, 3.0), y = lie_test::uniform(rng, -3.0, 3.0);
      // Build the locked rotation in double so it is exactly at the lock up to S's rounding.
      const Eigen::Matrix3d R = ulc::rotation_from_rpy(r, pitch, y);
      const ulc::Vec3<S> got = ulc::rpy_from_rotation(ulc::Mat3<S>(R.cast<S>()));
      INFO("roll " << r << " yaw " << y << " got " << got.transpose());
      CHECK(std::abs(double(got.y()) - pitch) < Tol<S>::log);
      CHECK(got.x() == S(0));  // the convention at the lock: all of the turn goes to yaw
      CHECK(max_diff(ulc::rotation_from_rpy(got.x(), got.y(), got.z()), R) < 20 * Tol<S>::exact);
    }
  }
  // Near the lock roll and yaw are ill-conditioned, but the rotation must still be reproduced.
  for (const double gap : {1e-4, 1e-7, 1e-10}) {
    for (int i = 0; i < 20; ++i) {
      const double r = lie_test::uniform(rng, -3.0, 3.0), y = lie_test::uniform(rng, -3.0, 3.0);
      const Eigen::Matrix3d R = ulc::rotation_from_rpy(r, kPi / 2 - gap, y);
      const ulc::Vec3<S> got = ulc::rpy_from_rotation(ulc::Mat3<S>(R.cast<S>()));
      INFO("gap " << gap << " got " << got.transpose());
      CHECK(max_diff(ulc::rotation_from_rpy(got.x(), got.y(), got.z()), R) < 20 * Tol<S>::exact);
      CHECK(std::abs(double(got.x())) <= kPi);
      CHECK(std::abs(double(got.y())) <= kPi / 2 + 1e-6);
    }
  }
}
