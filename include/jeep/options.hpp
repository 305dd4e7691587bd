// The options of JEEP and of its stages (scan preparation, local map, odometry, map
// registration, start search, acceptance, second look, scan-to-scan) and the small functions
// that build their defaults, apart from the algorithms: a user's file that only sets options
// (ulc/calibrate/options.hpp, pair_calibration.hpp) includes this light header instead of the
// stages' heavy ones (TBB, solvers, the stages' inline functions; docs/design.md). Each stage's
// header includes it and documents the conventions the fields refer to: "the header comment"
// or "the top" in a struct's comments below means its stage's header (AcceptanceOptions:
// acceptance.hpp, SecondLookOptions: second_look.hpp).
#pragma once

#include <cstddef>
#include <vector>

#include "ulc/core/registration_types.hpp"

namespace jeep {

using ulc::RegistrationOptions;

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

/// The pose phase inside JEEP: denser scans (the calibration phase maps them), both stages
/// always, tighter tolerances; a handful of frames, so speed matters less than in odometry.
inline OdometryOptions jeep_pose_phase_options() {
  OdometryOptions o;
  o.scan.map_voxel = 0.4;
  o.scan.registration_voxel = 0.75;
  o.map.min_point_distance = 0.3;
  o.single_stage = false;
  o.translation_tolerance = 1e-4;
  o.rotation_tolerance = 1e-5;
  return o;
}

struct MapStage {
  double source_voxel = 0.25;  ///< m
  RegistrationOptions registration;
};

struct MapRegistrationOptions {
  double target_voxel = 0.3;  ///< m
  ulc::PlaneCloudOptions planes;
  std::vector<MapStage> stages;
};

/// One stage: gate, Geman-McClure scale and source resolution; tolerances 1e-4 m, 1e-5 rad.
inline MapStage map_stage(double source_voxel, double gate, double kernel,
                          int max_iterations = 30) {
  MapStage s;
  s.source_voxel = source_voxel;
  s.registration.max_iterations = max_iterations;
  s.registration.max_correspondence_distance = gate;
  s.registration.kernel = ulc::RobustKernel::geman_mcclure(kernel);
  s.registration.inlier_distance = 0.1;
  return s;
}

/// Coarse to fine from the paper's disturbance (5 deg, 2 m) to the data's accuracy.
inline MapRegistrationOptions default_map_registration() {
  MapRegistrationOptions o;
  o.stages = {map_stage(1.0, 4.0, 1.0), map_stage(0.5, 1.5, 0.3), map_stage(0.4, 0.6, 0.1),
              map_stage(0.4, 0.3, 0.03)};
  return o;
}

struct AcceptanceOptions {
  double voxel = 0.5;                     ///< m, both maps' resolution for the evidence
  double gate = 1.0;                      ///< m, "near": a plane of the other map within this
  double inlier_distance = 0.1;           ///< m, "agreeing": the success threshold of the paper
  double min_off_ground_overlap = 0.25;   ///< see the header comment
  double min_directional_overlap = 0.10;  ///< the floor over all six directions
  double min_condition = 1e-3;            ///< as RegistrationOptions::min_condition
  std::size_t min_agreeing = 100;
};

struct ScanScanOptions {
  ScanOptions scan = [] {
    ScanOptions o;
    o.map_voxel = 0.25;
    o.deskew = false;
    return o;
  }();
  MapRegistrationOptions registration = default_map_registration();
  AcceptanceOptions acceptance;
};

struct StartSearchOptions {
  bool enabled = true;
  double rotation_step = 5.0 * 3.14159265358979323846 / 180.0;  ///< rad, the paper's disturbance
  double translation_step = 2.0;                                ///< m, the paper's disturbance
  double same_basin_rotation = 1.0 * 3.14159265358979323846 / 180.0;  ///< rad
  double same_basin_translation = 0.3;                                ///< m
  /// Basins further than this from the initial extrinsic are not candidates: the initial
  /// guess is trusted to within twice the paper's disturbance.
  double reach_rotation = 10.0 * 3.14159265358979323846 / 180.0;  ///< rad
  double reach_translation = 5.0;                                 ///< m
};

struct SecondLookOptions {
  bool enabled = false;                  ///< opt-in: see "Measured" at the top
  double min_off_ground_overlap = 0.10;  ///< below: no second look
  double max_gap_translation = 0.02;     ///< m
  double max_gap_rotation = 0.1 * 3.14159265358979323846 / 180.0;  ///< rad
  std::size_t min_returned = 10;                                   ///< of the twelve starts
  double return_translation = 0.01;                                ///< m
  double return_rotation = 0.05 * 3.14159265358979323846 / 180.0;  ///< rad
};

struct JeepOptions {
  std::size_t frames = 5;  ///< K, frame pairs used
  int max_rounds = 10;     ///< more rounds without settling is a failure
  OdometryOptions odometry = jeep_pose_phase_options();
  MapRegistrationOptions calibration = default_map_registration();
  /// The first calibration phase also starts from turned and shifted copies of the initial
  /// extrinsic and keeps the best basin (start_search.hpp).
  StartSearchOptions start_search;
  /// Calibration stages (the last ones) used after the first round, when C moves little.
  std::size_t refine_stages = 2;
  /// Settled when a round moves C and every pose by less than this: a fourth of the 2 cm and
  /// a fifth of the 0.1 deg JEEP aims at, a twentieth of the paper's success thresholds.
  double settle_translation = 0.005;  ///< m
  double settle_rotation = 3.5e-4;    ///< rad (0.02 deg)
  AcceptanceOptions acceptance;
  /// Opt-in: a refusal for the off-ground overlap alone gets a second look (second_look.hpp).
  SecondLookOptions second_look;
  /// Frame period when the timestamps cannot tell (a single frame): docs/design.md's 10 Hz.
  double default_period = 0.1;
  /// Once settled, meet map a registered to map b's planes halfway (two_way.hpp), so that
  /// swapping base and target gives the inverse extrinsic.
  bool two_way = true;
};

}  // namespace jeep
