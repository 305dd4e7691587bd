// What calibrate_pair (pipeline/calibrate.hpp) returns for one base/target pair. Light: it includes
// no algorithm, so that a file calling the pipeline compiles in seconds.
//
// Conventions this header owns:
//   - T_base_target maps target points into the base frame (docs/design.md): p_base = T * p_target.
//   - On success it is the last stage's output. On failure it is the input of the stage that
//     failed (TERRA's rotation or the initial guess; identity when TERRA failed), kept for
//     inspection only: `success` false means "do not use it".
//   - `status` is one word for programs (CalibrateStatus); `reason` is one human sentence that
//     names the stage and its own status. Each stage that ran leaves its report (terra, jeep,
//     hots).
//   - When HOTS fails, T_base_target keeps JEEP's extrinsic (or the initial guess) and success is
//     false; hots->extrinsic still holds what HOTS reached, for inspection.
//   - Times are wall-clock seconds (std::chrono::steady_clock): statistics, never decisions.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hots/refine_statistics.hpp"
#include "jeep/status.hpp"
#include "odometry/status.hpp"
#include "pipeline/map_terra_options.hpp"
#include "pipeline/options.hpp"
#include "pipeline/stages.hpp"
#include "terra/search_params.hpp"
#include "ulc/core/observability_types.hpp"
#include "ulc/core/registration_types.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

enum class CalibrateStatus {
  ok,
  invalid_input,     ///< bad options, empty inputs, frame_index past the end
  initial_required,  ///< no terra stage and no initial extrinsic
  terra_failed,      ///< TERRA found no rotation (see terra->status)
  jeep_failed,       ///< JEEP did not converge or its result was rejected (see jeep->status)
  hots_failed,       ///< the odometry before HOTS or HOTS itself failed (see hots->status)
  // What the data cannot vouch for (pipeline/vouch.hpp; the extrinsic is kept for inspection):
  time_offset_unestimated,  ///< no clock offset estimated or given, and a lag moves it (clock)
  point_times_missing,      ///< a LiDAR's sweeps could not be deskewed at this speed (point_times)
  /// The final problem leaves a direction of the extrinsic free (a straight road, a tunnel):
  /// `unobservable` names it; the extrinsic's other directions are the data's
  /// (pipeline/observability_verdict.hpp).
  degenerate,
  /// The result's own covariance does not vouch for it: more than a 5 % chance of lying beyond
  /// a success's 1 deg / 10 cm along some direction (pipeline/confidence.hpp; extrinsic kept).
  uncertain
};

inline const char* to_string(CalibrateStatus s) {
  switch (s) {
    case CalibrateStatus::ok:
      return "ok";
    case CalibrateStatus::invalid_input:
      return "invalid_input";
    case CalibrateStatus::initial_required:
      return "initial_required";
    case CalibrateStatus::terra_failed:
      return "terra_failed";
    case CalibrateStatus::jeep_failed:
      return "jeep_failed";
    case CalibrateStatus::time_offset_unestimated:
      return "time_offset_unestimated";
    case CalibrateStatus::point_times_missing:
      return "point_times_missing";
    case CalibrateStatus::degenerate:
      return "degenerate";
    case CalibrateStatus::uncertain:
      return "uncertain";
    default:
      return "hots_failed";
  }
}

/// One of TERRA's hypotheses the pipeline started from (terra_hypotheses.hpp) and what became of
/// it.
struct TerraHypothesis {
  TerraSource source = TerraSource::frames;  ///< frames or maps: the search it is an optimum of
  bool motion = false;  ///< the motion frame's rotation (terra_stage.hpp), not a search optimum
  Mat3d rotation = Mat3d::Identity();            ///< R_base_target
  double distance = 0.0;                         ///< eq:feature_dis
  std::size_t mask_count = 0;                    ///< eq:mask cells
  CalibrateStatus status = CalibrateStatus::ok;  ///< how the stages from it ended
  std::string reason;                            ///< why, when status is not ok
  double seconds = 0.0;                          ///< JEEP, odometry and HOTS from this hypothesis
  /// JEEP's off-ground overlap when JEEP accepted the answer from this hypothesis and the
  /// free-space check judged and passed it: what a static snapshot's contest compares
  /// (hypothesis_attempts.hpp).
  std::optional<double> off_ground_overlap;
};

/// The TERRA stage: a rotation from one frame of each LiDAR, or from each LiDAR's local map
/// over a short window from that frame (map_terra.hpp), no prior. The fields above `source`
/// describe the search whose rotation was kept.
struct TerraReport {
  terra::SearchStatus status = terra::SearchStatus::ok;
  std::string reason;
  Mat3d rotation = Mat3d::Identity();  ///< R_base_target found
  double distance = 0.0;               ///< eq:feature_dis at the rotation
  std::size_t mask_count = 0;          ///< cells in eq:mask at the rotation
  std::size_t frame_index = 0;         ///< the frame of each LiDAR used (the maps' first)
  std::size_t base_points = 0, target_points = 0;  ///< of the frames, or of the maps
  std::size_t lattice_size = 0;
  terra::SearchStats stats;  ///< rotations and seconds per stage, d1 used, ...
  double seconds = 0.0;      ///< the whole stage, lattice, maps and descriptors included
  TerraSource source = TerraSource::frames;  ///< what the kept search compared
  std::string
      source_reason;  ///< why (CalibrateOptions::tuning.terra_source.source, automatic rule)
  /// The single-frame search's mask count and status when it ran (automatic runs it first and
  /// keeps it unless its overlap is small), whatever source was kept.
  std::optional<std::size_t> frames_mask_count;
  terra::SearchStatus frames_status = terra::SearchStatus::ok;
  std::optional<LocalMapStats> base_map, target_map;  ///< when the maps were built
  /// The maps' ground and travel (motion_frame.hpp), when the maps were built; when it
  /// overruled the search (motion->used), `rotation` is its rotation and the fields above
  /// `source` describe the search it overruled.
  std::optional<MotionReport> motion;
  /// The hypotheses the later stages started from, in the order tried (the first is the
  /// search's best, `rotation`), and the index of the one the result comes from (the first
  /// when none succeeded).
  std::vector<TerraHypothesis> hypotheses;
  std::size_t hypothesis_used = 0;
};

/// The JEEP stage: extrinsic and poses over the first K frame pairs.
struct JeepReport {
  jeep::JeepStatus status = jeep::JeepStatus::ok;
  std::string reason;
  Isometry3d initial = Isometry3d::Identity();    ///< the extrinsic JEEP started from
  Isometry3d extrinsic = Isometry3d::Identity();  ///< JEEP's last extrinsic (even if failed)
  int rounds = 0;
  std::size_t frame_pairs = 0;  ///< pairs used (<= JeepOptions::frames)
  /// On a parked rig, the frames stacked into JEEP's one pair (parked_stack.hpp); 0 otherwise.
  std::size_t stacked_frames_base = 0, stacked_frames_target = 0;
  /// ... and what its covariance was scaled by: the stacks' frames per cell (1 when unstacked).
  double stack_covariance_scale = 1.0;
  RegistrationStatus calibration_status =
      RegistrationStatus::ok;        ///< of the last map-to-map registration
  double final_cost = 0.0;           ///< of the last map-to-map registration
  std::size_t final_inliers = 0;     ///< of the last map-to-map registration
  double final_rmse = 0.0;           ///< m
  bool accepted = false;             ///< the acceptance rule's verdict
  double overlap = 0.0;              ///< acceptance: agreeing / near map points
  double directional_overlap = 0.0;  ///< acceptance: the same, weakest direction (a floor)
  double off_ground_overlap = 0.0;   ///< acceptance: weakest direction off the ground (judged)
  /// Two-way step (jeep/two_way.hpp): applied, and how far the two directions disagreed.
  bool two_way = false;
  double two_way_gap_translation = 0.0;  ///< m
  double two_way_gap_rotation = 0.0;     ///< rad
  /// The first calibration phase's start search (jeep/start_search.hpp): distinct basins
  /// scored, and the start whose basin won (0: the initial extrinsic's own).
  std::size_t start_basins = 0;
  std::size_t start_chosen = 0;
  /// JEEP failed (rejected or not settled) and HOTS ran from its extrinsic to judge it
  /// (CalibrateOptions::tuning.hypotheses.hots_judges_jeep): the pair's status says which won.
  bool judged_by_hots = false;
  /// The final map-to-map registration's observability of the extrinsic (the acceptance's
  /// agreeing points, ulc/core/observability.hpp), when the maps agree and the free-space check
  /// did not refuse the answer as a look-alike (else nothing: the information of a
  /// misregistration says nothing about the scene).
  std::optional<Observability> observability;
  double seconds = 0.0;
  /// The target's largest speed over the pairs (a's twists carried to b's origin), m/s: what
  /// an unestimated clock offset or an undeskewed sweep turns into a translation error.
  double target_speed_mps = 0.0;
  /// A static snapshot's answer judged by the free space the base saw (pipeline/free_space.hpp);
  /// nothing when the check did not run (a moving rig, the check off, JEEP failed).
  std::optional<FreeSpaceVerdict> free_space;
};

/// How far the HOTS stage got.
enum class HotsRun {
  refined,          ///< hots::refine ran: HotsReport::status says how it ended
  skipped,          ///< too few frames for HOTS: the previous stage's extrinsic stands
  odometry_failed,  ///< the odometry before it gave no poses: HOTS did not run
  /// HOTS ran, but the odometry it built on did not see the motion along some direction
  /// (odometry_condition below StageTuning::min_odometry_condition): its answer is not used
  odometry_degenerate,
};

/// The HOTS stage: odometry over every frame from frame_index, then hots::refine.
struct HotsReport {
  HotsRun run = HotsRun::refined;
  hots::RefineStatus status = hots::RefineStatus::ok;  ///< when run is refined
  std::string reason;
  odometry::OdometryStatus odometry_status = odometry::OdometryStatus::ok;
  std::string odometry_reason;
  std::size_t frames_base = 0, frames_target = 0;  ///< frames given to odometry and HOTS
  std::size_t odometry_failed_steps = 0;
  double odometry_condition = 0.0;  ///< odometry::median_condition of the odometry's steps
  Isometry3d initial = Isometry3d::Identity();    ///< the extrinsic HOTS started from
  Isometry3d extrinsic = Isometry3d::Identity();  ///< HOTS's extrinsic (even if failed)
  double time_offset_s = 0.0;                     ///< t_base_clock = t_target_clock + offset
  Mat6d covariance_6x6 = Mat6d::Zero();           ///< [rho; phi], left
  hots::RefineStatistics statistics;
  std::vector<std::pair<double, double>> spread_curve;  ///< (offset s, spread), last pass
  /// The whole-sequence step's observability of the extrinsic (ulc/core/observability.hpp),
  /// when that step ran.
  std::optional<Observability> observability;
  double odometry_seconds = 0.0;
  /// Which odometry gave HOTS its poses (StageTuning::hots_odometry resolved: joint or base),
  /// and why (pipeline/odometry_choice.hpp).
  HotsOdometry odometry = HotsOdometry::joint;
  std::string odometry_choice;
  /// The base's own odometry was run before this attempt (by the caller, as a rig does for its
  /// targets, or for an earlier TERRA hypothesis) and reused: odometry_seconds leaves it out.
  bool odometry_reused = false;
  /// HOTS's preparation of the base's frames (deskewed, thinned, its hierarchy and bridges) came
  /// from an earlier hypothesis or target on the same poses: its time is not in seconds.
  bool base_prepared_reused = false;
  double seconds = 0.0;  ///< hots::refine alone
  /// Whether the rig stood still (pipeline/stillness.hpp); nothing when the check did not run
  /// (too few frames, or it is off).
  std::optional<StillnessReport> stillness;
};

// What the data cannot vouch for (pipeline/vouch.hpp, docs/pipeline.md "Clocks and point
// times"): the clock offset when no stage estimated it, and the LiDARs without per-point times.

/// Where the result's clock offset comes from.
enum class ClockSource {
  given,              ///< CalibrateOptions::time_offset_s (--synced-clocks, --time-offset)
  estimated_by_hots,  ///< HOTS's time synchronisation
  not_estimated       ///< neither: clocks assumed synchronised; clock.verdict says if it matters
};

inline const char* to_string(ClockSource s) {
  switch (s) {
    case ClockSource::given:
      return "given";
    case ClockSource::estimated_by_hots:
      return "estimated_by_hots";
    default:
      return "not_estimated";
  }
}

/// The clock offset's effect on a translation nobody synchronised (vouch.hpp).
struct ClockReport {
  ClockSource source = ClockSource::not_estimated;
  double speed_mps = 0.0;             ///< the target's largest speed over JEEP's frames
  double translation_per_ms_m = 0.0;  ///< how far 1 ms of offset moves the translation
  /// slow (no plausible offset matters), parked (the rig stood still: stillness.hpp),
  /// lag_within_bar, lag_exceeds_bar, lag_unobservable,
  /// or empty when the source is given or estimated.
  std::string verdict;
  bool lag_checked = false;  ///< the lag was estimated from both LiDARs' rotation rates
  double lag_s = 0.0;        ///< t_base = t_target + lag, as the motions show it (not applied)
  double lag_sigma_s = 0.0;
  std::size_t lag_samples = 0;  ///< target frames compared
  double lag_window_s = 0.0;    ///< seconds of frames the lag was estimated over
  std::string note;             ///< one plain sentence (the result file's "clock.note")
};

/// Where a LiDAR's per-point times come from.
enum class PointTimeSource {
  per_point,                 ///< the frames carry them
  synthesised_from_azimuth,  ///< none in the frames; from each point's azimuth (sweep_times.hpp)
  none                       ///< none: the sweeps are not deskewed
};

inline const char* to_string(PointTimeSource s) {
  switch (s) {
    case PointTimeSource::per_point:
      return "per_point";
    case PointTimeSource::synthesised_from_azimuth:
      return "synthesised_from_azimuth";
    default:
      return "none";
  }
}

struct PointTimesReport {
  PointTimeSource source = PointTimeSource::per_point;
  std::size_t frames_without = 0;  ///< frames (from frame_index) without per-point times
  std::string note;                ///< what was done, and why (empty for per_point)
};

struct StageTimings {
  double terra = 0.0;
  double jeep = 0.0;
  double odometry = 0.0;  ///< the odometry over all frames that feeds HOTS
  double hots = 0.0;
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
  std::optional<HotsReport> hots;
  /// The known offset (CalibrateOptions::time_offset_s) or HOTS's when it succeeded; otherwise
  /// 0 (clocks assumed synchronised).
  double time_offset_s = 0.0;
  /// Of T_base_target, from the last stage's final problem (HOTS's, or JEEP's when HOTS did
  /// not run or skipped itself): xi = [rho; phi] with T_true = exp(xi) T (left, base frame; m,
  /// rad). docs/pipeline.md, "The covariance".
  std::optional<Mat6d> covariance_6x6;
  /// Observability of the extrinsic in the final problem (pipeline/observability_verdict.hpp):
  /// which problem was judged ("hots": the whole-sequence step; "jeep": the final map-to-map
  /// registration; empty: none), its weakest direction's share, and the directions it leaves
  /// free (non-empty exactly when status is degenerate).
  std::string observability_problem;
  double weakest_share = 0.0;
  std::vector<UnobservableDirection> unobservable;
  StageTimings timing_s;
  // What the data cannot vouch for (vouch.hpp): the clock offset's provenance and effect
  // (set whenever JEEP's or HOTS's translation is the answer), and each LiDAR's point times.
  std::optional<ClockReport> clock;
  PointTimesReport point_times_base, point_times_target;
  /// What this call did for the base alone (StageTuning::hots_odometry base; empty otherwise, or
  /// when HOTS did not run): its odometry and HOTS's preparation of its frames. A caller with
  /// another target of the same base passes it on as CalibrateOptions::base_work, as
  /// calibrate_rig does, and it is not done again.
  BaseWork base_work;

  bool ok() const { return success; }
  /// HOTS refined the extrinsic, so the answer is HOTS's (however its refinement ended).
  bool hots_refined() const { return hots && hots->run == HotsRun::refined; }
};

}  // namespace ulc
