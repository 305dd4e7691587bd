// One attempt of the pipeline: the stages after TERRA (JEEP, then the odometry and HOTS) from
// one starting extrinsic, on the frames from frame_index on.
//
//   - JEEP (jeep.hpp) over the first JeepOptions::frames frame pairs. When it fails and HOTS may
//     judge it (HypothesisOptions::hots_judges_jeep, a moving rig, a finite extrinsic), HOTS
//     runs from JEEP's extrinsic and decides: its success overrules JEEP, its refusal is JEEP's
//     failure.
//   - HOTS: the multi-LiDAR odometry (StageTuning::odometry) over ALL frames from frame_index
//     (StageTuning::hots_odometry base: the base's own, run by the first attempt and reused),
//     then hots::refine on those frames and poses. An odometry that could not register some
//     frames still feeds HOTS (its poses are predictions there); one that gives no poses ends
//     the attempt. With fewer than StageTuning::hots_min_frames frames per LiDAR, or on a rig
//     the stillness check found standing (stillness.hpp, judged by the caller into base), HOTS
//     is skipped after TERRA or JEEP (a static rig has no motion for it); alone, it fails.
//   - A static rig (a snapshot of fewer frames than hots_min_frames, or parked): JEEP's answer
//     is also judged by the free space the base saw (free_space.hpp); refused, the attempt is
//     jeep_failed.
//   - A failure "points at the start" when JEEP failed or HOTS's cross links refused the
//     extrinsic (extrinsic_unconfirmed): the next TERRA hypothesis is then worth a try.
//   - Progress: "jeep", "odometry", "hots", with the attempt's label (" (hypothesis k)").
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hots/hots.hpp"
#include "jeep/jeep.hpp"
#include "odometry/run_odometry.hpp"
#include "pipeline/free_space.hpp"
#include "pipeline/observability_verdict.hpp"
#include "pipeline/odometry_choice.hpp"
#include "pipeline/options.hpp"
#include "pipeline/pair_calibration.hpp"
#include "pipeline/parked_stack.hpp"
#include "pipeline/stillness.hpp"
#include "pipeline/text_format.hpp"
#include "ulc/core/frame_range.hpp"
#include "ulc/core/lidar_sequence.hpp"

namespace ulc {
namespace calibrate_detail {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// What every attempt reads: both LiDARs' sequences from frame_index on (b's timestamps on a's
/// clock when the offset is known), the options and which stages run.
template <class FramesA, class FramesB>
struct AttemptInputs {
  LidarSequence<FrameRange<FramesA>> a;
  LidarSequence<FrameRange<FramesB>> b;
  const CalibrateOptions& options;
  hots::RefineOptions hots;  ///< StageTuning::hots with a known clock offset applied
  bool run_terra = false, run_jeep = false, run_hots = false;
  /// The base's own work (StageTuning::hots_odometry base): the caller's
  /// (CalibrateOptions::base_work), else filled by the first attempt that runs HOTS and reused
  /// by every later one, since it depends on neither the target nor the extrinsic.
  mutable BaseWork base;
  /// Which odometry HOTS starts from: StageTuning::hots_odometry resolved (odometry_choice.hpp).
  OdometryChoice odometry;
  /// On a parked rig, JEEP's one frame pair: each LiDAR's first frames stacked
  /// (parked_stack.hpp), made by the first attempt and reused by every later one.
  mutable std::shared_ptr<const ParkedStack<FrameRange<FramesA>, FrameRange<FramesB>>> stack;
  /// HOTS runs, on a moving rig: it can judge a start.
  bool can_verify() const { return run_hots && !static_rig(); }
  std::size_t frames_left() const { return std::min(a.size(), b.size()); }
  /// Too few frames for HOTS (a snapshot), or a rig that stood still for all of them.
  bool static_rig() const { return frames_left() < options.tuning.hots_min_frames || parked(); }
  /// The stillness check found the rig standing still (pipeline/stillness.hpp).
  bool parked() const { return base.stillness && base.stillness->still; }
};

/// How the stages of one attempt ended, and whether the failure points at its start.
struct StageOutcome {
  CalibrateStatus status = CalibrateStatus::ok;
  std::string reason;
  bool points_at_start = false;
};

/// One attempt's running state.
struct Attempt {
  Isometry3d extrinsic;        ///< the stage's start, then its result
  std::string label;           ///< "" or " (hypothesis k)", for progress
  bool hots_may_judge = true;  ///< a failed JEEP may be judged by HOTS
  std::string jeep_failure;    ///< set when JEEP failed and HOTS judges its extrinsic
  PairCalibration& out;
};

inline void notify(const CalibrateOptions& o, const std::string& stage, double fraction) {
  if (o.progress) o.progress(stage, fraction);
}

/// A stage's (done, total) counts as its fraction of the progress bar.
inline odometry::ProgressFn count_progress(const CalibrateOptions& o, std::string stage) {
  if (!o.progress) return {};
  return [&o, stage](std::size_t done, std::size_t total) {
    o.progress(stage, total ? static_cast<double>(done) / static_cast<double>(total) : 1.0);
  };
}

/// The target's largest speed over JEEP's pairs: a's body twists (per second) carried to b's
/// origin, |rho + phi x t| with t the extrinsic's translation.
inline double target_speed(const jeep::JeepResult& j) {
  double fastest = 0.0;
  for (const Vec6d& xi : j.twists)
    fastest =
        std::max(fastest, (xi.head<3>() + xi.tail<3>().cross(j.extrinsic.translation())).norm());
  return fastest;
}

inline JeepReport jeep_report(const jeep::JeepResult& j, const Isometry3d& initial,
                              double seconds) {
  JeepReport r;
  r.status = j.status;
  r.reason = j.reason;
  r.initial = initial;
  r.extrinsic = j.extrinsic;
  r.rounds = j.rounds;
  r.frame_pairs = j.pairs.size();
  r.calibration_status = j.calibration.status;
  r.final_cost = j.calibration.cost;
  r.final_inliers = j.calibration.inliers;
  r.final_rmse = j.calibration.rmse;
  r.accepted = j.acceptance.accepted;
  r.overlap = j.acceptance.overlap;
  r.directional_overlap = j.acceptance.directional_overlap;
  r.off_ground_overlap = j.acceptance.off_ground_overlap;
  r.two_way = j.two_way.applied;
  r.two_way_gap_translation = j.two_way.gap_translation;
  r.two_way_gap_rotation = j.two_way.gap_rotation;
  r.start_basins = j.start_search.basins;
  r.start_chosen = j.start_search.chosen;
  r.observability = jeep_observability(j.acceptance, j.extrinsic);
  r.seconds = seconds;
  r.target_speed_mps = target_speed(j);
  return r;
}

/// A JEEP that ran to its end without a usable extrinsic's verdict (rejected, or not settled)
/// with a finite extrinsic: HOTS can judge it (HypothesisOptions::hots_judges_jeep).
inline bool hots_can_judge(jeep::JeepStatus status, const Isometry3d& extrinsic) {
  return (status == jeep::JeepStatus::rejected || status == jeep::JeepStatus::not_converged) &&
         extrinsic.matrix().allFinite();
}

/// The same from a JEEP stage's report (for callers that ran JEEP through calibrate_pair and
/// run HOTS themselves, as the benchmarks do).
inline bool hots_can_judge(const JeepReport& j) {
  return hots_can_judge(j.status, j.extrinsic);
}

/// JEEP's options for this call: on a parked rig, one frame pair (its stacked frames), as a
/// snapshot's. JEEP's pose phase over five frames of a standing rig let its poses slide where
/// single frames of a rig's VLP-16s pin little, and let a twin through (bench_covariance
/// --parked --parked-seconds 2, seeds 1-3: 3 answers beyond 1 deg / 10 cm in 117 with five
/// frames: docs/experiments/parked_recordings.md).
///
/// On a static rig judged by the free-space check and the two-way verdict, JEEP accepts maps
/// that agree off the ground at the check's lower overlap (FreeSpaceOptions::
/// min_off_ground_overlap); free_space_step lets such an answer stand only when both judged it
/// (unvouched_overlap_refusal).
template <class FA, class FB>
jeep::JeepOptions jeep_options(const AttemptInputs<FA, FB>& in) {
  jeep::JeepOptions o = in.options.tuning.jeep;
  if (in.parked()) o.frames = 1;
  const FreeSpaceOptions& free_space = in.options.tuning.free_space;
  if (in.static_rig() && free_space.enabled && o.two_way)
    o.acceptance.min_off_ground_overlap =
        std::min(o.acceptance.min_off_ground_overlap, free_space.min_off_ground_overlap);
  return o;
}

/// The calibration phase's finest source voxel (m); 0 without stages (JEEP refuses those).
inline double finest_source_voxel(const jeep::JeepOptions& o) {
  return o.calibration.stages.empty() ? 0.0 : o.calibration.stages.back().source_voxel;
}

/// JEEP from `start` on the call's frames, or on a parked rig on its stacked frames (made once).
template <class FA, class FB>
jeep::JeepResult run_jeep_stage(const AttemptInputs<FA, FB>& in, const Isometry3d& start,
                                const std::string& stage) {
  const jeep::JeepOptions options = jeep_options(in);
  const odometry::ProgressFn progress = count_progress(in.options, stage);
  if (!in.parked())
    return jeep::run_jeep(in.a.frames, in.a.times, in.b.frames, in.b.times, start, options,
                          progress);
  if (!in.stack)
    in.stack = std::make_shared<const ParkedStack<FrameRange<FA>, FrameRange<FB>>>(
        parked_stack(in.a.frames, in.a.times, in.b.frames, in.options.tuning.parked_stack,
                     finest_source_voxel(options)));
  const auto& s = *in.stack;
  return jeep::run_jeep(s.a, s.times_a, s.b, s.times_b, start, options, progress);
}

/// The JEEP stage; an outcome when it ends the attempt.
template <class FA, class FB>
std::optional<StageOutcome> jeep_step(const AttemptInputs<FA, FB>& in, Attempt& at) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string stage = "jeep" + at.label;
  notify(in.options, stage, 0.0);
  const jeep::JeepResult j = run_jeep_stage(in, at.extrinsic, stage);
  at.out.jeep = jeep_report(j, at.extrinsic, seconds_since(t0));
  if (in.stack) {
    at.out.jeep->stacked_frames_base = in.stack->frames_a;
    at.out.jeep->stacked_frames_target = in.stack->frames_b;
    at.out.jeep->stack_covariance_scale = in.stack->covariance_scale();
  }
  at.out.timing_s.jeep = at.out.jeep->seconds;
  notify(in.options, stage, 1.0);
  if (!j.ok()) {
    at.jeep_failure = std::string("JEEP: ") + jeep::to_string(j.status) + ": " + j.reason;
    at.out.jeep->judged_by_hots = at.hots_may_judge &&
                                  in.options.tuning.hypotheses.hots_judges_jeep &&
                                  in.can_verify() && hots_can_judge(j.status, j.extrinsic);
    if (!at.out.jeep->judged_by_hots)
      return StageOutcome{CalibrateStatus::jeep_failed, at.jeep_failure, true};
  }
  at.extrinsic = j.extrinsic;
  if (j.ok()) {
    at.out.T_base_target = at.extrinsic;
    at.out.covariance_6x6 = j.covariance_6x6;
    if (in.stack && at.out.covariance_6x6)
      *at.out.covariance_6x6 *= in.stack->covariance_scale();  // parked_stack.hpp: views
  }
  return std::nullopt;
}

/// One refusal of the free-space check in words: what share of which of the target's judged
/// samples (points or rays) contradicts what the base saw, and the bound it passed.
inline std::string refusal_text(const char* verb, double share, const char* samples,
                                std::size_t contradicting, std::size_t judged, const char* where,
                                double bound) {
  char text[320];
  std::snprintf(text, sizeof text,
                "JEEP: its extrinsic %s %.0f %% of the target's judged %s (%zu of %zu) %s (at most "
                "%.0f %%): a look-alike of the scene, not the mount",
                verb, 100.0 * share, samples, contradicting, judged, where, 100.0 * bound);
  return text;
}

/// The free-space check's refusal, in words; empty when the answer stands (too few judged, or
/// neither share above its bound).
inline std::string free_space_refusal(const FreeSpaceVerdict& v, const FreeSpaceOptions& o) {
  if (v.judged >= o.min_points && v.share() > o.max_share)
    return refusal_text("puts", v.share(), "points", v.contradicting, v.judged,
                        "where the base's rays passed through empty space", o.max_share);
  if (v.rays_judged >= o.min_points && v.through_share() > o.max_through_share)
    return refusal_text("sends", v.through_share(), "rays", v.rays_through, v.rays_judged,
                        "through surfaces the base saw and the target did not",
                        o.max_through_share);
  return "";
}

/// A static snapshot's JEEP answer against the free space the base saw (free_space.hpp); an
/// outcome when it is refused. Not judged when the target moved more than half a voxel between
/// the two frames (JEEP's target speed times their time gap): the check compares one frame
/// of each as if taken at one instant.
template <class FA, class FB>
std::optional<StageOutcome> free_space_step(const AttemptInputs<FA, FB>& in, Attempt& at) {
  const FreeSpaceOptions& o = in.options.tuning.free_space;
  if (!o.enabled || !at.out.jeep || !at.out.jeep->accepted) return std::nullopt;
  JeepReport& report = *at.out.jeep;
  const double gap_s = std::fabs(in.a.times[0] - in.b.times[0]);
  if (report.target_speed_mps * gap_s <= 0.5 * o.voxel)
    report.free_space = free_space_verdict(in.a.frames[0], in.b.frames[0], at.extrinsic, o);
  std::string why = report.free_space ? free_space_refusal(*report.free_space, o) : std::string();
  if (!why.empty()) {
    // A look-alike's registration says nothing about the scene: its information is not
    // judged for a free direction (observability_verdict.hpp), so the refusal names the cause.
    report.observability.reset();
    return StageOutcome{CalibrateStatus::jeep_failed, std::move(why), true};
  }
  why = unvouched_overlap_refusal(report.off_ground_overlap,
                                  in.options.tuning.jeep.acceptance.min_off_ground_overlap,
                                  report.free_space, report.two_way, o);
  if (why.empty()) return std::nullopt;
  return StageOutcome{CalibrateStatus::jeep_failed, std::move(why), true};
}

/// A failure after JEEP: when HOTS was judging a failed JEEP, HOTS's refusal is JEEP's failure.
inline StageOutcome failed_after_jeep(const Attempt& at, CalibrateStatus status, std::string why,
                                      bool points_at_start) {
  if (at.jeep_failure.empty()) return StageOutcome{status, std::move(why), points_at_start};
  return StageOutcome{CalibrateStatus::jeep_failed,
                      at.jeep_failure + " (HOTS, run from its extrinsic to judge it: " + why + ")",
                      points_at_start};
}

/// Why HOTS has no motion to work with: too few frames, or a rig that stood still.
template <class FA, class FB>
std::string no_motion_reason(const AttemptInputs<FA, FB>& in) {
  if (in.parked()) return in.base.stillness->reason + " (HOTS needs a moving rig)";
  return "only " + std::to_string(in.frames_left()) + " frame(s) per LiDAR from frame " +
         std::to_string(in.options.frame_index) + " (HOTS needs " +
         std::to_string(in.options.tuning.hots_min_frames) + " of a moving rig)";
}

/// HOTS skipped on a static rig (a snapshot, or parked): the previous stage's extrinsic stands.
template <class FA, class FB>
StageOutcome skip_hots(const AttemptInputs<FA, FB>& in, Attempt& at) {
  HotsReport h;
  h.run = HotsRun::skipped;
  h.reason = no_motion_reason(in) + "; the extrinsic is the previous stage's";
  h.initial = h.extrinsic = at.extrinsic;
  if (in.base.stillness) h.stillness = *in.base.stillness;
  at.out.hots = h;
  return {CalibrateStatus::ok, "", false};
}

/// Odometry gave a pose to every frame (possibly predicted ones): HOTS can start.
inline bool odometry_usable(const odometry::OdometryResult& odo) {
  return odo.ok() || odo.status == odometry::OdometryStatus::registration_failed;
}

inline HotsReport odometry_report(const odometry::OdometryResult& odo, const Isometry3d& initial,
                                  double odometry_seconds) {
  HotsReport h;
  h.run = odometry_usable(odo) ? HotsRun::refined : HotsRun::odometry_failed;
  h.odometry_status = odo.status;
  h.odometry_reason = odo.reason;
  h.frames_base = odo.poses_a.size();
  h.frames_target = odo.poses_b.size();
  h.odometry_failed_steps = odo.failed_steps;
  h.odometry_condition = odometry::median_condition(odo);
  h.initial = initial;
  h.extrinsic = initial;
  h.odometry_seconds = odometry_seconds;
  return h;
}

inline void add_refine(HotsReport& h, const hots::RefineResult& r, double seconds) {
  h.status = r.status;
  h.reason = r.reason;
  h.extrinsic = r.extrinsic;
  h.time_offset_s = r.time_offset_s;
  h.covariance_6x6 = r.covariance_6x6;
  h.statistics = r.statistics;
  h.spread_curve = r.spread_curve;
  h.observability = hots_observability(r.statistics.sequence);
  h.base_prepared_reused = r.statistics.prepared_a_reused;
  h.seconds = seconds;
}

/// What an unconfirmed extrinsic's cross links say: kept links refuting it, so it is likely
/// wrong; or none kept, so nothing is known of it, with what the weak links saw (reported, not
/// used: hots/hots.hpp).
inline std::string unconfirmed_hint(const hots::RefineStatistics& st) {
  const std::string attempted = std::to_string(st.cross_links_attempted);
  if (st.link_verdict == hots::LinkVerdict::kept_links_refute)
    return "; " + std::to_string(st.cross_links_agreeing) + " of " + attempted + " agree" +
           (st.links_judged_within_reach ? " (kept by their overlap within the base's reach)"
                                         : "") +
           ": the extrinsic before HOTS is likely wrong (TERRA's rotation or the initial guess)";
  const char* within = st.links_judged_within_reach ? " within the base's reach" : "";
  return "; 0 of " + attempted + " registered with enough overlap" + within + " (" +
         std::to_string(st.cross_links_converged) + " converged, with a median inlier ratio of " +
         fixed(st.cross_link_inlier_ratio_median, 2) + ", and " +
         std::to_string(st.cross_links_weak_agreeing) + " of the " +
         std::to_string(st.cross_links_weak) +
         " weak ones agree): neither confirmed nor refuted (a drive on which the LiDARs "
         "see more of the same surfaces can judge it)";
}

/// One sentence for a failed HOTS, with what to do about it.
inline std::string hots_failure(const hots::RefineResult& h) {
  std::string why = std::string("HOTS: ") + hots::to_string(h.status) + ": " + h.reason;
  if (h.status == hots::RefineStatus::extrinsic_unconfirmed) why += unconfirmed_hint(h.statistics);
  if (h.status == hots::RefineStatus::time_offset_untrusted)
    why +=
        "; a longer drive with turns and speed changes pins it down, and synchronised clocks "
        "are said so with time_offset_s = 0 (ulc calibrate --synced-clocks)";
  return why;
}

/// Why HOTS's answer cannot be used although HOTS's own checks passed: the odometry it built on
/// did not see the motion along some direction (StageTuning::min_odometry_condition); empty
/// when it did.
inline std::string odometry_doubt(const HotsReport& h, const StageTuning& tuning) {
  if (h.odometry_condition >= tuning.min_odometry_condition) return "";
  char text[96];
  std::snprintf(text, sizeof(text), "%.4f (at least %.4f needed)", h.odometry_condition,
                tuning.min_odometry_condition);
  return std::string(
             "the odometry's registrations leave a direction nearly free (median "
             "condition ") +
         text +
         ": a tunnel or a straight road): the trajectory HOTS builds on, and a clock offset "
         "read from it, are not observed along that direction";
}

/// HOTS's starting poses from the extrinsic C (in.odometry): the base's own
/// odometry carried to the target (run once per call, or given by the caller), or the joint one.
template <class FA, class FB>
odometry::OdometryResult hots_odometry(const AttemptInputs<FA, FB>& in, const Isometry3d& C,
                                       const std::string& stage) {
  const StageTuning& tuning = in.options.tuning;
  const odometry::ProgressFn progress = count_progress(in.options, stage);
  if (in.odometry.odometry != HotsOdometry::base)
    return odometry::run_odometry(in.a.frames, in.a.times, in.b.frames, in.b.times, C,
                                  tuning.odometry, progress);
  if (!in.base.odometry)
    in.base.odometry = std::make_shared<const odometry::OdometryResult>(
        odometry::run_single_odometry(in.a.frames, in.a.times, tuning.odometry, progress));
  return odometry::with_target_poses(*in.base.odometry, in.b.times, C,
                                     tuning.odometry.time_offset_s);
}

/// The odometry over every frame, then hots::refine on its poses.
template <class FA, class FB>
StageOutcome hots_step(const AttemptInputs<FA, FB>& in, Attempt& at) {
  const std::string odometry_stage = "odometry" + at.label, hots_stage = "hots" + at.label;
  auto t0 = std::chrono::steady_clock::now();
  notify(in.options, odometry_stage, 0.0);
  const bool base_only = in.odometry.odometry == HotsOdometry::base;
  const bool odometry_reused = base_only && in.base.odometry != nullptr;
  const odometry::OdometryResult odo = hots_odometry(in, at.extrinsic, odometry_stage);
  at.out.timing_s.odometry = seconds_since(t0);
  at.out.hots = odometry_report(odo, at.extrinsic, at.out.timing_s.odometry);
  at.out.hots->odometry_reused = odometry_reused;
  at.out.hots->odometry = in.odometry.odometry;
  at.out.hots->odometry_choice = in.odometry.why;
  if (in.base.stillness) at.out.hots->stillness = *in.base.stillness;
  if (at.out.hots->run == HotsRun::odometry_failed)
    return failed_after_jeep(
        at, CalibrateStatus::hots_failed,
        std::string("HOTS: odometry: ") + odometry::to_string(odo.status) + ": " + odo.reason,
        !at.jeep_failure.empty());
  notify(in.options, odometry_stage, 1.0);
  notify(in.options, hots_stage, 0.0);
  auto a = in.a;
  auto b = in.b;
  a.poses = odo.poses_a;
  b.poses = odo.poses_b;
  t0 = std::chrono::steady_clock::now();
  const hots::RefineResult h = hots::refine(
      a, b, at.extrinsic, in.hots, [&](double share) { notify(in.options, hots_stage, share); },
      base_only ? &in.base.hots : nullptr);
  at.out.timing_s.hots = seconds_since(t0);
  add_refine(*at.out.hots, h, at.out.timing_s.hots);
  at.out.hots->time_offset_s += at.out.time_offset_s;  // back to b's own clock
  if (!h.ok())
    return failed_after_jeep(
        at, CalibrateStatus::hots_failed, hots_failure(h),
        h.status == hots::RefineStatus::extrinsic_unconfirmed || !at.jeep_failure.empty());
  if (std::string doubt = odometry_doubt(*at.out.hots, in.options.tuning); !doubt.empty()) {
    at.out.hots->run = HotsRun::odometry_degenerate;
    at.out.hots->reason = doubt;
    return failed_after_jeep(at, CalibrateStatus::hots_failed,
                             "HOTS: odometry_degenerate: " + doubt, !at.jeep_failure.empty());
  }
  notify(in.options, hots_stage, 1.0);
  at.out.T_base_target = h.extrinsic;
  at.out.time_offset_s += h.time_offset_s;
  at.out.covariance_6x6 = h.covariance_6x6;
  return {CalibrateStatus::ok, "", false};
}

/// JEEP and HOTS (as the stages ask) from `start`, into `out`.
template <class FA, class FB>
StageOutcome run_attempt(const AttemptInputs<FA, FB>& in, const Isometry3d& start,
                         std::string label, bool hots_may_judge, PairCalibration& out) {
  Attempt at{start, std::move(label), hots_may_judge, {}, out};
  out.T_base_target = start;
  if (in.run_jeep) {
    if (auto ended = jeep_step(in, at)) return *ended;
    if (in.static_rig())
      if (auto ended = free_space_step(in, at)) return *ended;
  }
  if (!in.run_hots) return {CalibrateStatus::ok, "", false};
  if (in.static_rig() && (in.run_terra || in.run_jeep)) return skip_hots(in, at);
  if (in.parked()) return {CalibrateStatus::hots_failed, "HOTS: " + no_motion_reason(in), false};
  return hots_step(in, at);
}

}  // namespace calibrate_detail
}  // namespace ulc
