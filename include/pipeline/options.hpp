// The options of ulc::calibrate_pair (pipeline/calibrate.hpp), in two tiers: CalibrateOptions holds
// what a caller decides (stages, frames, clocks, threads, progress); StageTuning holds each
// stage's own tuning, whose structs live beside their stages (docs/pipeline.md lists every
// field). Light on purpose: it includes the stages' option headers only,
// never the algorithms, so that a file calling the pipeline compiles in seconds
// (docs/BENCHMARKS.md, "Compile time").
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hots/options.hpp"
#include "jeep/options.hpp"
#include "odometry/options.hpp"
#include "pipeline/free_space_options.hpp"
#include "pipeline/hypothesis_options.hpp"
#include "pipeline/map_terra_options.hpp"
#include "pipeline/odometry_choice_options.hpp"
#include "pipeline/stages.hpp"
#include "pipeline/stillness_options.hpp"
#include "pipeline/vouch_options.hpp"
#include "terra/search_params.hpp"
#include "ulc/core/types.hpp"

namespace odometry {
struct OdometryResult;  // odometry/run_odometry.hpp
}  // namespace odometry
namespace hots {
template <typename S>
struct PreparedLidar;  // hots/refine_state.hpp
}  // namespace hots

namespace ulc {

/// Which odometry gives HOTS its starting poses (StageTuning::hots_odometry).
enum class HotsOdometry {
  /// The multi-LiDAR odometry (odometry/run_odometry.hpp): both LiDARs' scans in every step,
  /// the target's through the extrinsic being tried.
  joint,
  /// The base LiDAR's own odometry, carried to the target through the extrinsic
  /// (odometry::with_target_poses). It depends neither on the target nor on the extrinsic, so
  /// one run serves every TERRA hypothesis of a call and every target of a rig (rig.hpp): 8.3 s
  /// against the joint one's 21.8 s on the 60 s 64-32 drive, the same extrinsic. Where the
  /// target's scans steady the poses (a Horizon base; an Avia target on a 10 s drive) HOTS
  /// agrees with fewer cross links and its covariance grows
  /// (docs/experiments/hots_base_odometry.md).
  base,
  /// The pipeline chooses (pipeline/odometry_choice.hpp): base on a drive of at least
  /// StageTuning::odometry_choice.min_duration_s whose base sees all around, joint otherwise. The
  /// default.
  automatic,
};

inline const char* to_string(HotsOdometry o) {
  switch (o) {
    case HotsOdometry::base:
      return "base";
    case HotsOdometry::automatic:
      return "automatic";
    default:
      return "joint";
  }
}

/// What a call did for the base LiDAR alone (StageTuning::hots_odometry base), for another call
/// on the same base frames from the same frame_index with the same tuning: a rig's targets share
/// it (rig.hpp). Each part is run when first needed and then reused.
struct BaseWork {
  /// The base's own odometry over its frames from frame_index (tuning.odometry).
  std::shared_ptr<const odometry::OdometryResult> odometry;
  /// HOTS's preparation of the base's frames on those poses: deskewed and thinned frames, the
  /// hierarchy and its bridges (hots::refine's prepared_a; used only when built from them).
  std::shared_ptr<hots::PreparedLidar<float>> hots;
  /// Whether the rig stood still over the base's frames from frame_index
  /// (pipeline/stillness.hpp).
  std::shared_ptr<const StillnessReport> stillness;
};

/// Called with the running stage's name ("terra", "jeep", "odometry", "hots") and its fraction
/// done.
using CalibrateProgress = std::function<void(const std::string& stage, double fraction)>;

/// Each stage's tuning; the defaults are the paper's where it gives one.
struct StageTuning {
  terra::SearchParams terra;        ///< N = 10000, d1 = 20 m, d2 = 5 m, alpha = 2, 10/1 deg strides
  TerraSourceOptions terra_source;  ///< frames or local maps (map_terra_options.hpp)
  HypothesisOptions hypotheses;     ///< TERRA's later optima tried in turn (not in the paper)
  jeep::JeepOptions jeep;           ///< K = 5 frame pairs, at most 10 rounds
  odometry::OdometryOptions odometry;  ///< the odometry over all frames that feeds HOTS
  HotsOdometry hots_odometry = HotsOdometry::automatic;  ///< which LiDARs it registers
  OdometryChoiceOptions odometry_choice;  ///< hots_odometry automatic: the rule's thresholds
  hots::RefineOptions hots;               ///< windows of 5, 3 layers, time synchronisation on
  /// Single frames or a static rig (fewer frames than this per LiDAR from frame_index): HOTS
  /// has no motion to work with, so after TERRA or JEEP it is skipped (stages.hots says so) and
  /// their extrinsic is the answer; as the only stage it fails.
  std::size_t hots_min_frames = 10;
  /// A rig that stood still for the whole recording (pipeline/stillness.hpp) is calibrated as a
  /// static snapshot: HOTS is skipped, it has no motion to work with.
  StillnessOptions stillness;
  /// ... and JEEP takes each LiDAR's first frames stacked into one cloud (parked_stack.hpp).
  ParkedStackOptions parked_stack;
  /// HOTS's answer is used only when the odometry it built on saw the motion: the median
  /// condition of its steps (odometry::median_condition) at least this, else hots_failed with
  /// stages.hots.status odometry_degenerate. In a tunnel the odometry follows its motion model
  /// along the tunnel: the two LiDARs' trajectories lag each other there (read as a clock
  /// offset: 8 s drives 13-43 ms off, trusted by HOTS's own checks, translations 11-39 cm off)
  /// and the submaps are placed wrongly along it (with the clocks given: 11.6 and 12.5 cm off,
  /// ok). Degenerate drives 0.003-0.014, the others 0.067 and up: 0.03 lies between
  /// (docs/experiments/degenerate_scenes.md).
  double min_odometry_condition = 0.03;
  /// What the data cannot vouch for: an unestimated clock offset, frames without point times
  /// (pipeline/vouch.hpp).
  VouchOptions vouch;
  /// A static snapshot's JEEP answer is refused when it puts the target's points where the
  /// base saw through empty space (pipeline/free_space.hpp).
  FreeSpaceOptions free_space;
};

/// What a caller of calibrate_pair decides.
struct CalibrateOptions {
  std::vector<Stage> stages{Stage::terra, Stage::jeep, Stage::hots};
  std::size_t frame_index = 0;        ///< TERRA's frame, and the first frame of the others
  std::optional<Isometry3d> initial;  ///< T_base_target guess, used when terra does not run
  /// The clocks' offset when it is known (t_base = t_target + offset; 0 for synchronised
  /// clocks): every stage reads b's timestamps moved onto a's clock, HOTS does not estimate an
  /// offset (nor check one) and the result reports this one. Unset: HOTS estimates it.
  std::optional<double> time_offset_s;
  /// Worker threads for this call (a TBB arena of this size); 0 = TBB's default (all cores, or
  /// the caller's own arena or global_control limit). The result does not depend on it.
  std::size_t threads = 0;
  CalibrateProgress progress;  ///< optional
  StageTuning tuning;
  /// The base's work from an earlier call on the same base (PairCalibration::base_work), with
  /// tuning.hots_odometry base: a rig's targets share it (rig.hpp). Empty: the call does it when
  /// HOTS needs it.
  BaseWork base_work;
};

}  // namespace ulc
