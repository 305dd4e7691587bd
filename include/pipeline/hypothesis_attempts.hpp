// The stages after TERRA from each of its hypotheses (terra_hypotheses.hpp), and which answer
// the call keeps (not in the paper, whose TERRA hands its single best rotation on).
//
//   - A moving rig, HOTS among the stages: the hypotheses run in turn while what followed one
//     points at its rotation (JEEP failed, or HOTS's cross links disagree) and HOTS can judge
//     the next; the first success wins (HypothesisOptions::count, fallback).
//   - A static snapshot (fewer than StageTuning::hots_min_frames frames, the free-space check
//     judging JEEP's answer, free_space.hpp): no HOTS can judge an answer, so only an accepted one
//     opens a contest. When the first hypothesis's answer passed JEEP's acceptance and the
//     free-space check, the next HypothesisOptions::snapshot_rivals hypotheses run too, and of the
//     answers that passed both the one whose target sees most of the base's scene off the ground
//     (JEEP's off_ground_overlap) wins; ties keep the better-ranked hypothesis. A few frames of a
//     moving rig hold one as well when their first pair was taken together (the check judges it
//     only then). A look-alike of the street (its forward/backward twin) overlaps the base's walls
//     and poles less than the mount does. A snapshot whose first answer failed tries no other: a
//     later hypothesis accepted alone was wrong more often than right
//     (docs/experiments/free_space_check.md).
//
// Nothing here throws; deterministic (each attempt is; the choice is ordered comparisons).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>

#include "pipeline/attempt.hpp"
#include "pipeline/free_space_options.hpp"
#include "pipeline/observability_verdict.hpp"
#include "pipeline/pair_calibration.hpp"
#include "pipeline/terra_stage.hpp"

namespace ulc {
namespace calibrate_detail {

/// Ends a call: status, reason and the total time into the result.
struct Finish {
  PairCalibration& result;
  std::chrono::steady_clock::time_point start;
  PairCalibration operator()(CalibrateStatus status, std::string reason) const {
    judge_observability(result, status, reason);
    result.status = status;
    result.success = status == CalibrateStatus::ok;
    result.reason = std::move(reason);
    result.timing_s.total = seconds_since(start);
    return result;
  }
};

inline TerraHypothesis hypothesis_entry(const terra::RotationCandidate& c, TerraSource source) {
  TerraHypothesis h;
  h.source = source;
  h.rotation = c.rotation;
  h.distance = c.distance;
  h.mask_count = c.mask_count;
  return h;
}

inline void add_timings(StageTimings& into, const StageTimings& t) {
  into.jeep += t.jeep;
  into.odometry += t.odometry;
  into.hots += t.hots;
}

/// The stages' reports and outputs of one attempt into the result (timings are summed apart).
inline void take_stages(PairCalibration& r, const PairCalibration& attempt) {
  r.jeep = attempt.jeep;
  r.hots = attempt.hots;
  r.T_base_target = attempt.T_base_target;
  r.time_offset_s = attempt.time_offset_s;
  r.covariance_6x6 = attempt.covariance_6x6;
}

/// What a snapshot's contest compares: JEEP's off-ground overlap of an answer that JEEP
/// accepted and the free-space check judged and passed (at least FreeSpaceOptions::min_points
/// judged: the contest is held only where the base's rays vouch for the answers), -inf for any
/// other.
inline double contest_score(const PairCalibration& attempt, const StageOutcome& outcome,
                            const FreeSpaceOptions& free_space) {
  const auto& j = attempt.jeep;
  const bool vouched = outcome.status == CalibrateStatus::ok && j && j->accepted && j->free_space &&
                       j->free_space->judged >= free_space.min_points;
  return vouched ? j->off_ground_overlap : -std::numeric_limits<double>::infinity();
}

/// One hypothesis's attempt, how it ended (listed in stages.terra.hypotheses) and its score in
/// a snapshot's contest.
struct HypothesisRun {
  PairCalibration attempt;
  StageOutcome outcome;
  double contest_score = -std::numeric_limits<double>::infinity();
};

/// The stages from hypothesis k, its entry in r.terra->hypotheses and its timings in r's.
template <class FA, class FB>
HypothesisRun run_hypothesis(const AttemptInputs<FA, FB>& in, const StartRotations& starts,
                             std::size_t k, PairCalibration& r) {
  const auto t0 = std::chrono::steady_clock::now();
  HypothesisRun run;
  run.attempt.time_offset_s = r.time_offset_s;
  const std::string label = k == 0 ? "" : " (hypothesis " + std::to_string(k + 1) + ")";
  run.outcome = run_attempt(in, starts.start(k), label, k < starts.first_fallback, run.attempt);
  TerraHypothesis entry = hypothesis_entry(starts.candidates[k], starts.sources[k]);
  entry.motion = k == 0 && starts.motion_first;
  entry.status = run.outcome.status;
  entry.reason = run.outcome.reason;
  entry.seconds = seconds_since(t0);
  run.contest_score = contest_score(run.attempt, run.outcome, in.options.tuning.free_space);
  if (std::isfinite(run.contest_score)) entry.off_ground_overlap = run.contest_score;
  r.terra->hypotheses.push_back(entry);
  add_timings(r.timing_s, run.attempt.timing_s);
  return run;
}

/// A snapshot whose first hypothesis was accepted (`first`): its rivals run, the accepted
/// answer with the largest off-ground overlap is the call's (see the top of this file).
template <class FA, class FB>
PairCalibration snapshot_contest(const AttemptInputs<FA, FB>& in, const StartRotations& starts,
                                 HypothesisRun first, PairCalibration& r, const Finish& finish) {
  const std::size_t end = std::min({starts.first_fallback, starts.candidates.size(),
                                    1 + in.options.tuning.hypotheses.snapshot_rivals});
  HypothesisRun best = std::move(first);
  std::size_t best_k = 0;
  for (std::size_t k = 1; k < end; ++k) {
    HypothesisRun rival = run_hypothesis(in, starts, k, r);
    if (rival.contest_score <= best.contest_score) continue;
    best = std::move(rival);
    best_k = k;
  }
  take_stages(r, best.attempt);
  r.terra->hypothesis_used = best_k;
  return finish(best.outcome.status, best.outcome.reason);
}

/// A snapshot's first answer opens a contest: accepted, and judged by the free-space check (a
/// static rig: the check is skipped when the target moved between the two frames).
template <class FA, class FB>
bool opens_contest(const AttemptInputs<FA, FB>& in, const HypothesisRun& first) {
  return in.static_rig() && in.options.tuning.hypotheses.snapshot_rivals > 0 &&
         std::isfinite(first.contest_score);
}

/// TERRA's hypotheses in turn (see the top of this file): when what followed one points at its
/// rotation and HOTS can judge the next, the next runs. The first success wins (on a snapshot,
/// the contest's winner); with none, the best hypothesis's outcome is the answer.
template <class FA, class FB>
PairCalibration try_hypotheses(const AttemptInputs<FA, FB>& in, const StartRotations& starts,
                               PairCalibration& r, const Finish& finish) {
  HypothesisRun first;
  for (std::size_t k = 0; k < starts.candidates.size(); ++k) {
    HypothesisRun run = run_hypothesis(in, starts, k, r);
    if (k == 0 && opens_contest(in, run))
      return snapshot_contest(in, starts, std::move(run), r, finish);
    const StageOutcome& o = run.outcome;
    // A failure that does not point at the rotation (the views confirmed it, the clocks'
    // offset is untrusted, say) is this hypothesis's own answer; so is the best's when no other
    // can be judged.
    const bool next_worth_it =
        in.can_verify() && o.points_at_start && k + 1 < starts.candidates.size();
    if (o.status == CalibrateStatus::ok || (!next_worth_it && (k == 0 || !o.points_at_start))) {
      take_stages(r, run.attempt);
      r.terra->hypothesis_used = k;
      return finish(o.status, o.reason);
    }
    if (k == 0) first = std::move(run);
  }
  take_stages(r, first.attempt);
  r.terra->hypothesis_used = 0;
  return finish(first.outcome.status,
                first.outcome.reason + "; TERRA's next " +
                    std::to_string(r.terra->hypotheses.size() - 1) +
                    " hypotheses were not confirmed either (stages.terra.hypotheses)");
}

}  // namespace calibrate_detail
}  // namespace ulc
