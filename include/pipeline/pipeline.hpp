// The calibration pipeline's top floor: one base LiDAR a and one target LiDAR b in, the
// extrinsic T_base_target out (docs/design.md, "The house" and "Data flows one way"). This header
// holds the whole pipeline as templates on the frames' type (calibrate_pair_in_place); a user's
// file includes pipeline/calibrate.hpp instead, whose calibrate_pair runs it compiled once. The
// TERRA stage is terra_stage.hpp; the stages after it, from one start, attempt.hpp.
//
//   frames of a, b -> TERRA(a[i], b[i])              -> R0 (translation zero)
//                  -> JEEP(pairs from frame i on, R0) -> C1
//                  -> odometry(all frames from i on, C1) -> poses
//                  -> HOTS(all frames from i on, poses, C1) -> C2, clock offset, covariance
//
// Conventions this header owns (result conventions: calibrate/pair_calibration.hpp):
//   - Inputs: the frames of each LiDAR (any random-access container of clouds with point traits,
//     per-point times relative to the frame timestamp) and their timestamps (seconds, each
//     LiDAR's own clock, one per frame).
//   - frame_index i: TERRA uses frame i of each LiDAR, or each LiDAR's local map over a window
//     from frame i on, as tuning.terra_source says (terra_stage.hpp; stages.terra says which
//     and why). JEEP pairs frames by timestamp from frame i of each on and uses the first
//     JeepOptions::frames pairs. Frames before i are never touched.
//   - Stages: any ordered subset of terra, jeep, hots (stages.hpp); the default is all three
//     (docs/design.md). TERRA needs no prior and ignores `initial`; each later stage starts from
//     the previous stage's extrinsic, or from `initial` when it is the first, which is then
//     required (status initial_required without it).
//   - HOTS: multi-LiDAR odometry (tuning.odometry) over ALL frames of each LiDAR from frame i
//     on, with the extrinsic HOTS starts from (or the base's own odometry, run once per call or
//     given as options.base_work, and the target's poses through that extrinsic;
//     result.base_work hands it on: tuning.hots_odometry base, or automatic on a long drive of
//     an all-around base, odometry_choice.hpp, with the stages run again on the joint odometry
//     when that ends without a success), then hots::refine (tuning.hots) on
//     those frames and poses. Its extrinsic, clock offset and covariance become the result's. An
//     odometry that could not register some frames still feeds HOTS (its poses are predictions
//     there; the report counts them); an odometry that gives no poses, or a HOTS that fails, ends
//     the call with hots_failed, keeping the previous extrinsic. With fewer than
//     tuning.hots_min_frames frames per LiDAR (single frames, as in a static rig's snapshot), or
//     on a rig that stood still for the whole recording (stillness.hpp: judged once per base
//     before the attempts when JEEP or HOTS runs), HOTS is skipped after TERRA or JEEP:
//     stages.hots has status "skipped" and the reason. A HOTS whose
//     clock offset the drive does not pin down fails too (time_offset_untrusted: the extrinsic
//     would carry the offset's error times the speed); a caller who knows the clocks' offset sets
//     time_offset_s, and then no offset is estimated or checked.
//   - TERRA's hypotheses and HOTS as the judge (not in the paper): with HOTS on a moving rig, a
//     JEEP that was rejected or did not settle hands its extrinsic to HOTS
//     (tuning.hypotheses.hots_judges_jeep), and when the attempt from TERRA's best rotation fails
//     in a way that points at the rotation (JEEP failed, or HOTS's extrinsic_unconfirmed), TERRA's
//     next distinct optima run in turn (up to tuning.hypotheses.count); the first success wins.
//     When all of those fail, up to tuning.hypotheses.fallback more (the kept search's other
//     optima, then those of the search not kept) run, each needing JEEP's own acceptance before
//     HOTS. With none, the best one's failure is reported. On a static snapshot an accepted first
//     answer meets its rivals instead (tuning.hypotheses.snapshot_rivals; hypothesis_attempts.hpp).
//     stages.terra.hypotheses lists each one tried and its outcome; timings sum over all of them.
//     Each starts from its rotation and translation 0, or from the ground vote's lever arm when it
//     lies within vote_agree_deg of a confident vote's rotation (StartRotations::start).
//   - Degenerate verdict (observability_verdict.hpp): when the call ends, the final problem's
//     information for the extrinsic (HOTS's whole-sequence step, else JEEP's final
//     registration) is judged; a direction it leaves free makes the status degenerate, over
//     ok or a stage's failure, and `unobservable` names it.
//   - Progress: options.progress(stage, fraction in [0, 1]) on the calling thread; stages
//     "terra", "jeep", "odometry", "hots" (HOTS after each of its phases); a later hypothesis's
//     stages carry " (hypothesis k)".
//   - Threads: every stage is deterministic for any thread count, so is this.
//     CalibrateOptions::threads runs the call in a tbb::task_arena of that size.
//   - Nothing here throws, exits or prints; it compiles with -fno-exceptions.
#pragma once

#include <chrono>
#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <tbb/task_arena.h>

#include "pipeline/attempt.hpp"
#include "pipeline/hypothesis_attempts.hpp"
#include "pipeline/odometry_choice.hpp"
#include "pipeline/options.hpp"
#include "pipeline/pair_calibration.hpp"
#include "pipeline/point_times.hpp"
#include "pipeline/stages.hpp"
#include "pipeline/terra_stage.hpp"
#include "pipeline/vouch.hpp"
#include "ulc/core/frame_range.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

namespace calibrate_detail {

/// Why the inputs cannot be calibrated (an empty reason when they can).
struct InputCheck {
  CalibrateStatus status = CalibrateStatus::ok;
  std::string reason;
};

template <class FramesA, class FramesB>
InputCheck check_inputs(const FramesA& frames_a, const std::vector<double>& times_a,
                        const FramesB& frames_b, const std::vector<double>& times_b,
                        const CalibrateOptions& options) {
  if (std::string why = check_stages(options.stages); !why.empty())
    return {CalibrateStatus::invalid_input, "stages: " + why};
  if (frames_a.size() != times_a.size() || frames_b.size() != times_b.size())
    return {CalibrateStatus::invalid_input, "frame and timestamp counts differ"};
  if (options.time_offset_s && !std::isfinite(*options.time_offset_s))
    return {CalibrateStatus::invalid_input, "the known time offset is not finite"};
  if (std::string why = free_space_problem(options.tuning.free_space); !why.empty())
    return {CalibrateStatus::invalid_input, why};
  const std::size_t i = options.frame_index;
  if (i >= frames_a.size() || i >= frames_b.size())
    return {CalibrateStatus::invalid_input,
            "frame_index " + std::to_string(i) + " is past the end (base has " +
                std::to_string(frames_a.size()) + " frames, target " +
                std::to_string(frames_b.size()) + ")"};
  const auto& base_odometry = options.base_work.odometry;
  if (base_odometry && base_odometry->poses_a.size() != frames_a.size() - i)
    return {CalibrateStatus::invalid_input,
            "the base odometry given has " + std::to_string(base_odometry->poses_a.size()) +
                " poses, the base " + std::to_string(frames_a.size() - i) +
                " frames from frame_index"};
  if (has_stage(options.stages, Stage::terra)) return {};
  if (!options.initial)
    return {CalibrateStatus::initial_required,
            "stages without terra need an initial extrinsic (TERRA is what finds one without a "
            "guess)"};
  if (!options.initial->matrix().allFinite())
    return {CalibrateStatus::invalid_input, "the initial extrinsic is not finite"};
  return {};
}

/// A known clock offset: b's timestamps on a's clock, once, for every stage.
inline std::vector<double> on_base_clock(std::vector<double> times_b,
                                         const std::optional<double>& offset) {
  if (offset)
    for (double& t : times_b) t += *offset;
  return times_b;
}

/// HOTS's options with a known clock offset applied: nothing to estimate or check.
inline hots::RefineOptions hots_options(const CalibrateOptions& options) {
  hots::RefineOptions o = options.tuning.hots;
  if (options.time_offset_s) {
    o.synchronise_time = false;
    o.time_offset_s = 0.0;
    o.sequence.estimate_time_offset = false;
  }
  return o;
}

/// The TERRA stage into r.terra; the rotations to start from, or none when TERRA failed.
template <class FA, class FB>
std::optional<StartRotations> terra_step(const FA& frames_a, const std::vector<double>& times_a,
                                         const FB& frames_b, const std::vector<double>& times_b,
                                         const CalibrateOptions& options, PairCalibration& r) {
  const auto t0 = std::chrono::steady_clock::now();
  const TerraInputs<FA, FB> in(frames_a, times_a, frames_b, times_b, options);
  TerraReport report;
  const TerraSearches searches = run_terra_search(in, report);
  report.seconds = seconds_since(t0);
  notify(options, "terra", 1.0);  // the map search may not have run after the frames' share
  r.timing_s.terra = report.seconds;
  r.terra = std::move(report);
  if (!searches.ok()) return std::nullopt;
  return start_rotations(searches, r.terra->source, options.tuning.hypotheses,
                         options.tuning.terra_source.maps.motion);
}

/// The frames' point-time report before the stages: frames read on demand are counted as the
/// stages read them instead (a pass of its own would read the whole drive once more).
template <class Frames>
PointTimesReport point_times_before(const FrameRange<Frames>& frames) {
  if constexpr (std::is_base_of_v<FrameSource, Frames>)
    return {};
  else
    return point_times_of(frames);
}

/// The point times of frames read on demand, as the stages met them (point_times.hpp).
template <class FA, class FB>
void point_times_read(const AttemptInputs<FA, FB>& in, PairCalibration& r) {
  if constexpr (std::is_base_of_v<TimedSource, FA>)
    r.point_times_base = in.a.frames.container().untimed_report();
  if constexpr (std::is_base_of_v<TimedSource, FB>)
    r.point_times_target = in.b.frames.container().untimed_report();
}

/// The vouching on the result (vouch.hpp), with the point times the stages met.
template <class FA, class FB>
StageOutcome vouch_read(const AttemptInputs<FA, FB>& in, PairCalibration& r) {
  point_times_read(in, r);
  return vouch(in, r);
}

/// StageTuning::hots_odometry resolved on the base's frames and times the stages read, when
/// HOTS is asked for (odometry_choice.hpp); joint otherwise (no odometry runs).
template <class FA, class FB>
OdometryChoice hots_odometry_choice(const AttemptInputs<FA, FB>& in) {
  if (!in.run_hots) return {};
  return choose_odometry(in.options.tuning.hots_odometry, in.a.frames, in.a.times,
                         in.options.tuning.odometry_choice);
}

/// Whether the rig stood still over the base's frames (stillness.hpp), into in.base: judged
/// once per base when JEEP or HOTS will run on enough frames for HOTS (a rig's targets share
/// it, as they share the odometry).
template <class FA, class FB>
void judge_stillness_once(const AttemptInputs<FA, FB>& in) {
  const StageTuning& tuning = in.options.tuning;
  if (in.base.stillness || !(in.run_jeep || in.run_hots) || !tuning.stillness.enabled ||
      in.frames_left() < tuning.hots_min_frames)
    return;
  in.base.stillness = std::make_shared<const StillnessReport>(
      judge_stillness(in.a.frames, in.a.times, tuning.stillness));
}

/// TERRA alone: its best rotation is the answer.
inline PairCalibration terra_only(const StartRotations& starts, PairCalibration& r,
                                  const Finish& finish) {
  r.T_base_target.linear() = starts.candidates.front().rotation;
  r.terra->hypotheses.push_back(
      hypothesis_entry(starts.candidates.front(), starts.sources.front()));
  r.terra->hypotheses.back().motion = starts.motion_first;
  return finish(CalibrateStatus::ok, "");
}

/// The stages after TERRA (from `starts`, or from options.initial without TERRA), then the
/// vouching: the call's result.
template <class FA, class FB>
PairCalibration attempts_vouched(const AttemptInputs<FA, FB>& in, const StartRotations* starts,
                                 PairCalibration& r, const Finish& finish) {
  if (starts) {
    try_hypotheses(in, *starts, r, finish);
  } else {
    r.T_base_target = *in.options.initial;
    const StageOutcome o = run_attempt(in, *in.options.initial, "", true, r);
    finish(o.status, o.reason);
  }
  r.base_work = in.base;
  const StageOutcome v = vouch_read(in, r);
  return finish(v.status, v.reason);
}

/// attempts_vouched on the odometry in.odometry chose; when the automatic choice's base
/// odometry ends without a success, the stages run again on the joint odometry, whose result is
/// then the call's, the one the joint odometry alone gives (odometry_choice.hpp). A static rig
/// (parked, or too few frames for HOTS) runs no odometry, so a second run would repeat the first.
template <class FA, class FB>
PairCalibration attempts_on_chosen_odometry(const AttemptInputs<FA, FB>& in,
                                            const StartRotations* starts, PairCalibration& r,
                                            const Finish& finish) {
  if (!in.odometry.joint_if_refused || in.static_rig())
    return attempts_vouched(in, starts, r, finish);
  const PairCalibration before = r;
  PairCalibration result = attempts_vouched(in, starts, r, finish);
  if (result.success) return result;
  AttemptInputs<FA, FB> joint = in;
  joint.odometry = joint_after_refusal(in.odometry, to_string(r.status), r.reason);
  r = before;
  return attempts_vouched(joint, starts, r, finish);
}

/// The pipeline on validated inputs (calibrate_pair_in_place).
template <class FA, class FB>
PairCalibration run_pipeline(const FA& frames_a, const std::vector<double>& times_a,
                             const FB& frames_b, const std::vector<double>& times_b_own,
                             const CalibrateOptions& options, PairCalibration& r,
                             const Finish& finish) {
  const std::vector<double> times_b = on_base_clock(times_b_own, options.time_offset_s);
  r.time_offset_s = options.time_offset_s.value_or(0.0);
  const std::size_t i = options.frame_index;
  AttemptInputs<FA, FB> in{{FrameRange<FA>(frames_a, i), times_from(times_a, i), {}},
                           {FrameRange<FB>(frames_b, i), times_from(times_b, i), {}},
                           options,
                           hots_options(options),
                           has_stage(options.stages, Stage::terra),
                           has_stage(options.stages, Stage::jeep),
                           has_stage(options.stages, Stage::hots),
                           options.base_work,
                           {},
                           {}};
  in.odometry = hots_odometry_choice(in);
  judge_stillness_once(in);
  r.point_times_base = point_times_before(in.a.frames);
  r.point_times_target = point_times_before(in.b.frames);
  if (!in.run_terra) return attempts_on_chosen_odometry(in, nullptr, r, finish);
  const auto starts = terra_step(frames_a, times_a, frames_b, times_b, options, r);
  if (!starts)
    return finish(CalibrateStatus::terra_failed,
                  std::string("TERRA: ") + terra::to_string(r.terra->status) + ": " +
                      r.terra->reason + " (on " + to_string(r.terra->source) + ")");
  if (!in.run_jeep && !in.run_hots) {
    point_times_read(in, r);
    return terra_only(*starts, r, finish);
  }
  return attempts_on_chosen_odometry(in, &*starts, r, finish);
}

}  // namespace calibrate_detail

/// Calibrates target LiDAR b against base LiDAR a (see the conventions at the top), reading the
/// frames in place through the point traits: every stage is instantiated for FramesA and
/// FramesB. ulc::calibrate_pair (pipeline/calibrate.hpp) runs this once, on PointCloud<float>.
template <class FramesA, class FramesB>
PairCalibration calibrate_pair_in_place(const FramesA& frames_a, const std::vector<double>& times_a,
                                        const FramesB& frames_b, const std::vector<double>& times_b,
                                        const CalibrateOptions& options = {}) {
  PairCalibration r;
  r.stages = options.stages;
  const calibrate_detail::Finish finish{r, std::chrono::steady_clock::now()};
  const calibrate_detail::InputCheck check =
      calibrate_detail::check_inputs(frames_a, times_a, frames_b, times_b, options);
  if (!check.reason.empty()) return finish(check.status, check.reason);
  auto run = [&] {
    return calibrate_detail::run_pipeline(frames_a, times_a, frames_b, times_b, options, r, finish);
  };
  if (options.threads == 0) return run();
  tbb::task_arena arena(static_cast<int>(options.threads));
  return arena.execute(run);
}

}  // namespace ulc
