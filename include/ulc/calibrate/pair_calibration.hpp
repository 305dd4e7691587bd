// What calibrate_pair (ulc/calibrate.hpp) returns for one base/target pair.
//
// Conventions this header owns:
//   - T_base_target maps target points into the base frame (DESIGN.md): p_base = T * p_target.
//   - On success it is the last stage's output. On failure it is the input of the stage that
//     failed (TERRA's rotation or the initial guess; identity when TERRA failed), kept for
//     inspection only: `success` false means "do not use it".
//   - `status` is one word for programs (CalibrateStatus); `reason` is one human sentence that
//     names the stage and its own status. Each stage that ran leaves its report (terra, jeep).
//   - Times are wall-clock seconds (std::chrono::steady_clock): statistics, never decisions.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "terra/search_params.hpp"
#include "ulc/calibrate/stages.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

enum class CalibrateStatus {
  ok,
  invalid_input,        ///< bad options, empty inputs, frame_index past the end
  initial_required,     ///< no terra stage and no initial extrinsic
  stage_not_available,  ///< a stage this build cannot run yet (hots)
  terra_failed,         ///< TERRA found no rotation (see terra->status)
  jeep_failed           ///< JEEP did not converge or its result was rejected (see jeep->status)
};

inline const char* to_string(CalibrateStatus s) {
  switch (s) {
    case CalibrateStatus::ok:
      return "ok";
    case CalibrateStatus::invalid_input:
      return "invalid_input";
    case CalibrateStatus::initial_required:
      return "initial_required";
    case CalibrateStatus::stage_not_available:
      return "stage_not_available";
    case CalibrateStatus::terra_failed:
      return "terra_failed";
    default:
      return "jeep_failed";
  }
}

/// The TERRA stage: a rotation from one frame of each LiDAR, no prior.
struct TerraReport {
  std::string status;  ///< terra::to_string(SearchStatus)
  std::string reason;
  Mat3d rotation = Mat3d::Identity();  ///< R_base_target found
  double distance = 0.0;               ///< eq:feature_dis at the rotation
  std::size_t mask_count = 0;          ///< cells in eq:mask at the rotation
  std::size_t frame_index = 0;         ///< the frame of each LiDAR used
  std::size_t base_points = 0, target_points = 0;
  std::size_t lattice_size = 0;
  terra::SearchStats stats;  ///< rotations and seconds per stage, d1 used, ...
  double seconds = 0.0;      ///< the whole stage, lattice and descriptors included
};

/// The JEEP stage: extrinsic and poses over the first K frame pairs.
struct JeepReport {
  std::string status;  ///< jeep::to_string(JeepStatus)
  std::string reason;
  Isometry3d initial = Isometry3d::Identity();    ///< the extrinsic JEEP started from
  Isometry3d extrinsic = Isometry3d::Identity();  ///< JEEP's last extrinsic (even if failed)
  int rounds = 0;
  std::size_t frame_pairs = 0;     ///< pairs used (<= JeepOptions::frames)
  std::string calibration_status;  ///< of the last map-to-map registration
  double final_cost = 0.0;         ///< of the last map-to-map registration
  std::size_t final_inliers = 0;   ///< of the last map-to-map registration
  double final_rmse = 0.0;         ///< m
  bool accepted = false;           ///< the acceptance rule's verdict
  double overlap = 0.0;            ///< acceptance: agreeing / near map points
  double seconds = 0.0;
};

struct StageTimings {
  double terra = 0.0;
  double jeep = 0.0;
  double total = 0.0;  ///< the whole call
};

struct PairCalibration {
  bool success = false;
  CalibrateStatus status = CalibrateStatus::invalid_input;
  std::string reason;
  Isometry3d T_base_target = Isometry3d::Identity();
  std::vector<Stage> stages;  ///< as asked for
  std::optional<TerraReport> terra;
  std::optional<JeepReport> jeep;
  StageTimings timing_s;

  bool ok() const { return success; }
};

}  // namespace ulc
