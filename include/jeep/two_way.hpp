// Two-way calibration phase: the map-to-map registration (eq:calib_map) run in both directions
// and met halfway, so that swapping base and target gives the inverse extrinsic.
//
// Conventions this header owns:
//   - Forward: C = T_a_b puts map b's points on map a's planes (what JEEP's rounds compute).
//     Backward: D = T_b_a puts map a's points on map b's planes, from C^-1 with the given
//     (fine) stages. One-directional point-to-plane is not inverse-consistent: each direction
//     fits its own source's points, and on sparse or partial overlap the two minima can lie
//     centimetres apart (croon_0003: 2.8 cm).
//   - The answer is the SE(3) geodesic midpoint M = C exp(log(C^-1 D^-1) / 2). It is
//     inverse-consistent: midpoint(C^-1, D) = midpoint(C, D^-1)^-1 (exp and log commute with
//     conjugation), so a swapped run that finds the same two minima returns exactly M^-1.
//   - gap_* is the distance between C and D^-1: how much the two directions disagree, a
//     measure of how well the data pin the extrinsic down.
//   - The backward registration is used only when it ends ok or not_converged; otherwise C
//     stands and `applied` is false.
#pragma once

#include <vector>

#include "jeep/map_registration.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace jeep {

struct TwoWayResult {
  Isometry3d extrinsic = Isometry3d::Identity();  ///< the midpoint, or C when not applied
  bool applied = false;
  double gap_translation = 0.0;  ///< m, |C vs D^-1|
  double gap_rotation = 0.0;     ///< rad
  RegistrationResult<double> backward;
};

/// The inverse-consistent midpoint of two estimates of the same transform.
inline Isometry3d se3_midpoint(const Isometry3d& X, const Isometry3d& Y) {
  return X * ulc::se3_exp(ulc::Vec6d(0.5 * ulc::se3_log(Isometry3d(X.inverse() * Y))));
}

/// C (T_a_b, from map b onto map a's planes) met halfway by map a onto map b's planes.
template <typename S>
TwoWayResult two_way_extrinsic(const std::vector<Vec3<S>>& map_a, const std::vector<Vec3<S>>& map_b,
                               const Isometry3d& C, const MapRegistrationOptions& options) {
  TwoWayResult out;
  out.extrinsic = C;
  const auto planes_b = map_target(map_b, options);
  out.backward = register_maps(map_a, planes_b, Isometry3d(C.inverse()), options);
  const auto status = out.backward.status;
  if (status != ulc::RegistrationStatus::ok && status != ulc::RegistrationStatus::not_converged)
    return out;
  const Isometry3d backward_inverse = out.backward.pose.inverse();
  const Isometry3d gap = C.inverse() * backward_inverse;
  out.gap_translation = gap.translation().norm();
  out.gap_rotation = ulc::so3_log(gap.linear()).norm();
  out.extrinsic = se3_midpoint(C, backward_inverse);
  out.applied = true;
  return out;
}

}  // namespace jeep
