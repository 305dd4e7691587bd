// Map-to-map registration: the calibration phase of JEEP (the paper's eq:calib_map) and the
// scan-to-scan baseline (eq:calib_scan) share it.
//
// Conventions this header owns:
//   - register_maps(source, target, C0) estimates T_target_source: with map a as the target and
//     map b as the source (odometry.hpp's map frames) it is the extrinsic C = T_base_target.
//   - The target is voxel-downsampled at target_voxel and gets PCA planes (PlaneCloud); the
//     source is downsampled afresh for each stage at the stage's source_voxel. Stages run coarse
//     to fine (point_to_plane.hpp): a wide gate and a soft kernel on a sparse source find the
//     basin from far (the paper's disturbance: 5 deg and 2 m), a tight kernel on a dense source
//     gives the accuracy. The result is the last stage's, iterations summed.
//   - assemble_map stacks scans given in their sensor frames with their poses (eq:build_map).
#pragma once

#include <cstddef>
#include <vector>

#include "jeep/options.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/registration_target.hpp"
#include "ulc/core/registration_types.hpp"
#include "ulc/core/types.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace jeep {

using ulc::Isometry3d;
using ulc::RegistrationOptions;
using ulc::RegistrationResult;
using ulc::Vec3;

/// sum_k T_k * scan_k: the scans' points in the map frame.
template <typename S>
std::vector<Vec3<S>> assemble_map(const std::vector<const std::vector<Vec3<S>>*>& scans,
                                  const std::vector<Isometry3d>& poses) {
  std::vector<Vec3<S>> out;
  std::size_t n = 0;
  for (const auto* s : scans) n += s ? s->size() : 0;
  out.reserve(n);
  for (std::size_t k = 0; k < scans.size() && k < poses.size(); ++k) {
    if (!scans[k]) continue;
    for (const auto& p : *scans[k])
      out.push_back((poses[k] * p.template cast<double>()).template cast<S>());
  }
  return out;
}

template <typename S>
ulc::PointCloud<S> downsampled(const std::vector<Vec3<S>>& points, double voxel) {
  ulc::PointCloud<S> cloud;
  cloud.points = points;
  if (!(voxel > 0.0)) return cloud;
  return ulc::voxel_downsample(cloud, voxel).cloud;
}

/// The target side, built once and reused for several registrations.
template <typename S>
ulc::PlaneCloud<S> map_target(const std::vector<Vec3<S>>& target,
                              const MapRegistrationOptions& options) {
  return ulc::PlaneCloud<S>(downsampled(target, options.target_voxel), options.planes);
}

/// T_target_source through the stages, from `initial`.
template <typename S>
RegistrationResult<double> register_maps(const std::vector<Vec3<S>>& source,
                                         const ulc::PlaneCloud<S>& target,
                                         const Isometry3d& initial,
                                         const MapRegistrationOptions& options) {
  RegistrationResult<double> result;
  result.pose = initial;
  if (options.stages.empty()) {
    result.status = ulc::RegistrationStatus::invalid_input;
    result.reason = "no registration stage";
    return result;
  }
  int iterations = 0, solver_iterations = 0;
  for (const MapStage& stage : options.stages) {
    const ulc::PointCloud<S> points = downsampled(source, stage.source_voxel);
    const auto r = ulc::register_point_to_plane(points, target, result.pose, stage.registration);
    result = r;
    iterations += r.iterations;
    solver_iterations += r.solver_iterations;
    if (r.status == ulc::RegistrationStatus::too_few_correspondences ||
        r.status == ulc::RegistrationStatus::invalid_input)
      break;
  }
  result.iterations = iterations;
  result.solver_iterations = solver_iterations;
  return result;
}

}  // namespace jeep
