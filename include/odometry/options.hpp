// The options of the odometry (odometry.hpp, run_odometry.hpp) and of its parts (scan
// preparation, local map), apart from the algorithms: a file that only sets options includes
// this light header. Each part's header documents the conventions the fields refer to.
#pragma once

#include <cstddef>

namespace odometry {

struct ScanOptions {
  double min_range = 2.0;           ///< m
  double max_range = 100.0;         ///< m
  double map_voxel = 0.5;           ///< m, resolution of the dense points
  double registration_voxel = 1.0;  ///< m, resolution of the sparse points
  bool deskew = true;
};

struct LocalMapOptions {
  double voxel_size = 1.0;                ///< m
  std::size_t max_points_per_voxel = 20;  ///< cap per voxel
  double min_point_distance = 0.2;        ///< m, between points of one voxel
  double max_distance = 100.0;            ///< m, voxels further from the sensor are dropped
  double prune_step = 10.0;               ///< m of sensor travel between pruning checks
  std::size_t normal_k = 8;               ///< neighbours of each plane fit
  double min_planarity = 0.5;             ///< (l2 - l1) / l2 of a usable plane
};

struct OdometryOptions {
  ScanOptions scan;
  LocalMapOptions map;
  /// m, gate of the first registration stage (the second uses half of it). With
  /// single_stage, frames after the velocity is known get the second stage only.
  double gate = 2.0;
  double initial_gate = 3.0;   ///< m, first-stage gate while the velocity is unknown
  double coarse_kernel = 0.2;  ///< m, Geman-McClure scale of the first stage
  double fine_kernel = 0.05;   ///< m, of the second stage
  /// Off by default: the fine stage alone (Geman-McClure 5 cm) ignores the right planes once
  /// the constant-velocity prediction is a few decimetres off, e.g. when the vehicle brakes
  /// or accelerates; the next prediction is then worse and the odometry runs away (60 s 64-32
  /// drives, seeds 1-3: ATE 19-40 m with it, 0.17-0.37 m without, at the same speed;
  /// docs/experiments/odometry_runaway.md). JEEP's later rounds use it: they start from
  /// settled poses.
  bool single_stage = false;
  int max_iterations = 30;              ///< correspondence searches per stage
  double translation_tolerance = 5e-4;  ///< m, second stage (the first: 1e-3)
  double rotation_tolerance = 5e-5;     ///< rad, second stage (the first: 1e-4)
  double target_weight = 1.0;           ///< weight of b's residuals against a's
  double time_offset_s = 0.0;           ///< t_base_clock = t_target_clock + time_offset_s
  double max_pair_gap = 0.5;            ///< in base frame periods
  std::size_t min_correspondences = 30;
  double min_condition = 1e-3;  ///< registration_conditioning.hpp
};

}  // namespace odometry
