// Errors of an estimated pose against a reference, as the paper reports them (docs/design.md):
//   e_rot   = arccos((trace(R_gt^T R) - 1) / 2)     (the angle of the relative rotation)
//   e_trans = |t - t_gt|
// and the paper's success thresholds. The angle is computed as atan2(|skew part|, trace part)
// of R_gt^T R: equal to the arccos form for rotations, but accurate to relative rounding for tiny
// angles, where arccos near 1 loses half the digits, and never NaN for slightly non-orthonormal
// inputs. A NaN input gives a NaN error, which never counts as a success.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "ulc/core/angles.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// A final calibration succeeds when rotation error < 1 deg and translation error < 10 cm.
constexpr double kCalibrationMaxRotationDeg = 1.0;
constexpr double kCalibrationMaxTranslationM = 0.1;
/// A rotation initialisation (TERRA) succeeds when rotation error < 10 deg.
constexpr double kRotationInitMaxRotationDeg = 10.0;

/// The angle, in radians in [0, pi], of the rotation R_gt^T R.
template <typename DA, typename DB>
typename DA::Scalar rotation_error_rad(const Eigen::MatrixBase<DA>& R_gt,
                                       const Eigen::MatrixBase<DB>& R) {
  using S = typename DA::Scalar;
  using std::atan2;
  const Mat3<S> E = R_gt.transpose() * R;
  return atan2(vee(E).norm(), (E.trace() - S(1)) / S(2));
}

/// |t - t_gt|.
template <typename DA, typename DB>
typename DA::Scalar translation_error(const Eigen::MatrixBase<DA>& t_gt,
                                      const Eigen::MatrixBase<DB>& t) {
  return (t - t_gt).norm();
}

struct PoseError {
  double rotation_deg = 0;
  double translation_m = 0;
};

/// Rotation and translation error of T against T_gt, computed in double.
template <typename S>
PoseError pose_error(const Isometry3<S>& T_gt, const Isometry3<S>& T) {
  const Mat3d R_gt = T_gt.linear().template cast<double>();
  const Mat3d R = T.linear().template cast<double>();
  PoseError e;
  e.rotation_deg = rotation_error_rad(R_gt, R) * kDegPerRad;
  e.translation_m = translation_error(T_gt.translation().template cast<double>().eval(),
                                      T.translation().template cast<double>().eval());
  return e;
}

inline bool is_calibration_success(const PoseError& e) {
  return e.rotation_deg < kCalibrationMaxRotationDeg &&
         e.translation_m < kCalibrationMaxTranslationM;
}

inline bool is_rotation_init_success(const PoseError& e) {
  return e.rotation_deg < kRotationInitMaxRotationDeg;
}

}  // namespace ulc
