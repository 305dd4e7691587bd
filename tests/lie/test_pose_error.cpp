// The paper's error metrics and success thresholds.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <type_traits>

#include "lie_test_support.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"

using lie_test::kPi;

namespace {

constexpr double kDeg = kPi / 180.0;

// T_gt followed by a rotation of `deg` about z (in T_gt's frame) and a translation offset.
template <typename S>
ulc::Isometry3<S> perturbed(const ulc::Isometry3<S>& T_gt, double deg, const Eigen::Vector3d& dt) {
  ulc::Isometry3<S> T = T_gt;
  T.linear() = T_gt.linear() * Eigen::AngleAxis<S>(S(deg * kDeg), ulc::Vec3<S>::UnitZ()).matrix();
  T.translation() += dt.cast<S>();
  return T;
}

}  // namespace

TEMPLATE_TEST_CASE("pose_error against hand-computed values", "[lie][pose_error]", float, double) {
  using S = TestType;
  std::mt19937 rng(41);
  const double tol_deg = std::is_same_v<S, float> ? 1e-3 : 1e-9;
  for (int i = 0; i < 10; ++i) {
    const ulc::Isometry3<S> T_gt = lie_test::random_isometry<S>(rng);
    // 3 deg about z and a 3-4-5 offset of 5 cm.
    const ulc::PoseError e = ulc::pose_error(T_gt, perturbed(T_gt, 3.0, {0.03, -0.04, 0.0}));
    CHECK(e.rotation_deg == Approx(3.0).margin(tol_deg));
    CHECK(e.translation_m == Approx(0.05).margin(1e-6));
    CHECK_FALSE(ulc::is_calibration_success(e));
    CHECK(ulc::is_rotation_init_success(e));
    // The error is symmetric in its arguments.
    const ulc::PoseError back = ulc::pose_error(perturbed(T_gt, 3.0, {0.03, -0.04, 0.0}), T_gt);
    CHECK(back.rotation_deg == Approx(e.rotation_deg).margin(tol_deg));
  }
  // 180 degrees is the largest possible rotation error.
  const ulc::Isometry3<S> I = ulc::Isometry3<S>::Identity();
  CHECK(ulc::pose_error(I, perturbed(I, 180.0, Eigen::Vector3d::Zero())).rotation_deg ==
        Approx(180.0).margin(tol_deg));
  CHECK(ulc::pose_error(I, I).rotation_deg == 0.0);
  CHECK(ulc::pose_error(I, I).translation_m == 0.0);
}

TEST_CASE("success thresholds are strict and follow the paper", "[lie][pose_error]") {
  CHECK(ulc::kCalibrationMaxRotationDeg == 1.0);
  CHECK(ulc::kCalibrationMaxTranslationM == 0.1);
  CHECK(ulc::kRotationInitMaxRotationDeg == 10.0);
  CHECK(ulc::is_calibration_success({0.99, 0.099}));
  CHECK_FALSE(ulc::is_calibration_success({1.01, 0.05}));
  CHECK_FALSE(ulc::is_calibration_success({0.5, 0.101}));
  CHECK_FALSE(ulc::is_calibration_success({1.0, 0.05}));  // "< 1 deg": the bound itself fails
  CHECK(ulc::is_rotation_init_success({9.9, 5.0}));       // translation does not matter
  CHECK_FALSE(ulc::is_rotation_init_success({10.0, 0.0}));
  CHECK_FALSE(ulc::is_calibration_success({std::nan(""), 0.0}));
  CHECK_FALSE(ulc::is_rotation_init_success({std::nan(""), 0.0}));

  const ulc::Isometry3d I = ulc::Isometry3d::Identity();
  CHECK(ulc::is_calibration_success(ulc::pose_error(I, perturbed(I, 0.9, {0.0, 0.0, 0.09}))));
  CHECK_FALSE(ulc::is_calibration_success(ulc::pose_error(I, perturbed(I, 1.1, {0, 0, 0}))));
  CHECK(ulc::is_rotation_init_success(ulc::pose_error(I, perturbed(I, 9.5, {3.0, 0, 0}))));
  CHECK_FALSE(ulc::is_rotation_init_success(ulc::pose_error(I, perturbed(I, 10.5, {0, 0, 0}))));
}

TEST_CASE("rotation_error_rad is accurate for tiny angles and equals the arccos form",
          "[lie][pose_error]") {
  std::mt19937 rng(42);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Matrix3d R_gt = lie_test::random_rotation(rng);
    const Eigen::Vector3d axis = lie_test::random_axis(rng);
    for (const double tiny : {1e-7, 1e-10}) {
      const Eigen::Matrix3d R = R_gt * Eigen::AngleAxisd(tiny, axis).toRotationMatrix();
      CHECK(std::abs(ulc::rotation_error_rad(R_gt, R) - tiny) < 1e-6 * tiny);
    }
    // Where arccos is well conditioned (away from 0 and pi) both definitions agree.
    const double angle = lie_test::uniform(rng, 0.05, 3.0);
    const Eigen::Matrix3d R = R_gt * Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    const double by_arccos = std::acos(((R_gt.transpose() * R).trace() - 1.0) / 2.0);
    CHECK(std::abs(ulc::rotation_error_rad(R_gt, R) - by_arccos) < 1e-12);
    CHECK(std::abs(ulc::rotation_error_rad(R_gt, R) - angle) < 1e-12);
  }
  // The brief's bar: 1e-7 rad recovered within 1e-9.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1e-7, Eigen::Vector3d::UnitY()).toRotationMatrix();
  CHECK(std::abs(ulc::rotation_error_rad(Eigen::Matrix3d::Identity(), R) - 1e-7) < 1e-9);
  // Where the arccos form gives up entirely: at 1e-8 rad, (trace - 1) / 2 rounds to 1.
  const Eigen::Matrix3d R8 = Eigen::AngleAxisd(1e-8, Eigen::Vector3d::UnitY()).toRotationMatrix();
  CHECK(std::acos((R8.trace() - 1.0) / 2.0) == 0.0);
  CHECK(std::abs(ulc::rotation_error_rad(Eigen::Matrix3d::Identity(), R8) - 1e-8) < 1e-15);
}

TEST_CASE("translation_error is the Euclidean distance", "[lie][pose_error]") {
  CHECK(ulc::translation_error(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 3)) == 0.0);
  CHECK(ulc::translation_error(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 6, 3)) == 5.0);
  CHECK(ulc::translation_error(Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0, 0, -2)) == 2.0f);
}
