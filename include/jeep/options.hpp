// The options of JEEP and of its stages (map registration, start search, acceptance,
// scan-to-scan; the pose phase's odometry options are odometry/options.hpp's) and the small
// functions that build their defaults, apart from the algorithms: a user's file that only sets
// options includes this light header instead of the stages' heavy ones (TBB, solvers, the
// stages' inline functions; docs/design.md). Each stage's header includes it and documents the
// conventions the fields refer to: "the header comment" or "the top" in a struct's comments
// below means its stage's header (AcceptanceOptions: acceptance.hpp).
#pragma once

#include <cstddef>
#include <vector>

#include "odometry/options.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/registration_types.hpp"

namespace jeep {

using ulc::RegistrationOptions;

/// The pose phase inside JEEP: denser scans (the calibration phase maps them), both stages
/// always, tighter tolerances; a handful of frames, so speed matters less than in odometry.
inline odometry::OdometryOptions jeep_pose_phase_options() {
  odometry::OdometryOptions o;
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
  odometry::ScanOptions scan = [] {
    odometry::ScanOptions o;
    o.map_voxel = 0.25;
    o.deskew = false;
    return o;
  }();
  MapRegistrationOptions registration = default_map_registration();
  AcceptanceOptions acceptance;
};

struct StartSearchOptions {
  bool enabled = true;
  double rotation_step = 5.0 * ulc::kPi / 180.0;        ///< rad, the paper's disturbance
  double translation_step = 2.0;                        ///< m, the paper's disturbance
  double same_basin_rotation = 1.0 * ulc::kPi / 180.0;  ///< rad
  double same_basin_translation = 0.3;                  ///< m
  /// Basins further than this from the initial extrinsic are not candidates: the initial
  /// guess is trusted to within twice the paper's disturbance.
  double reach_rotation = 10.0 * ulc::kPi / 180.0;  ///< rad
  double reach_translation = 5.0;                   ///< m
};

struct JeepOptions {
  std::size_t frames = 5;  ///< K, frame pairs used
  int max_rounds = 10;     ///< more rounds without settling is a failure
  odometry::OdometryOptions odometry = jeep_pose_phase_options();
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
  /// Frame period when the timestamps cannot tell (a single frame): docs/design.md's 10 Hz.
  double default_period = 0.1;
  /// Once settled, meet map a registered to map b's planes halfway (two_way.hpp), so that
  /// swapping base and target gives the inverse extrinsic.
  bool two_way = true;
  /// Side of the cells whose points share their errors in the covariance of C (m; 0: every
  /// point independent). See jeep.hpp, covariance_6x6.
  double covariance_cell = 3.0;
};

}  // namespace jeep
