// The calibration pipeline's top floor: one base LiDAR a and one target LiDAR b in, the
// extrinsic T_base_target out (docs/design.md, "The house" and "Data flows one way"). This header
// holds the whole pipeline as templates on the frames' type (calibrate_pair_in_place); a user's
// file includes ulc/calibrate.hpp instead, whose calibrate_pair runs it compiled once.
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
//   - frame_index i: TERRA uses frame i of each LiDAR (the same index, so clock offsets do not
//     matter), or each LiDAR's local map over a window from frame i on (map_terra.hpp), as
//     CalibrateOptions::terra_source says. automatic runs the frame search first and keeps it
//     unless the sequences hold at least terra_maps_min_frames frames per LiDAR in the window
//     AND the frame search failed or overlaps in fewer than terra_maps_below_mask cells; then
//     the map search runs and wins when it succeeds with a larger mask. stages.terra says which
//     ("source") and why. JEEP pairs frames by timestamp from frame i of each on and uses the first
//     JeepOptions::frames pairs. Frames before i are never touched.
//   - Stages: any ordered subset of terra, jeep, hots (stages.hpp); the default is all three
//     (docs/design.md). TERRA needs no prior and ignores `initial`; each later stage starts from
//     the previous stage's extrinsic, or from `initial` when it is the first, which is then
//     required (status initial_required without it).
//   - HOTS: multi-LiDAR odometry (options.odometry) over ALL frames of each LiDAR from frame i
//     on, with the extrinsic HOTS starts from, then hots::refine (options.hots) on those frames
//     and poses. Its extrinsic, clock offset and covariance become the result's. An odometry
//     that could not register some frames still feeds HOTS (its poses are predictions there;
//     the report counts them); an odometry that gives no poses, or a HOTS that fails, ends the
//     call with hots_failed, keeping the previous extrinsic. With fewer than
//     hots_min_frames frames per LiDAR (single frames, as in a static rig's snapshot) HOTS is
//     skipped after TERRA or JEEP: stages.hots has status "skipped" and the reason. A HOTS
//     whose clock offset the drive does not pin down fails too (time_offset_untrusted: the
//     extrinsic would carry the offset's error times the speed); a caller who knows the
//     clocks' offset sets time_offset_s, and then no offset is estimated or checked.
//   - TERRA's hypotheses and HOTS as the judge (not in the paper): with HOTS on a moving rig,
//     a JEEP that was rejected or did not settle hands its extrinsic to HOTS (hots_judges_jeep),
//     and when the attempt from TERRA's best rotation fails in a way that points at the
//     rotation (JEEP failed, or HOTS's extrinsic_unconfirmed), TERRA's next distinct optima run
//     in turn (terra_hypotheses); the first success wins. When all of those fail, up to
//     terra_fallback_hypotheses more (the kept search's other optima, then those of the search
//     not kept) run, each needing JEEP's own acceptance before HOTS. With none, the best one's
//     failure is reported. stages.terra.hypotheses lists each one tried and its outcome; timings
//     sum over all of them.
//   - Progress: options.progress(stage, fraction in [0, 1]) on the calling thread; stages
//     "terra", "jeep", "odometry", "hots" (HOTS reports only 0 and 1); a later hypothesis's
//     stages carry " (hypothesis k)".
//   - Threads: every stage is deterministic for any thread count, so is this. Run inside a
//     tbb::task_arena to limit threads.
//   - Nothing here throws, exits or prints; it compiles with -fno-exceptions.
#pragma once

#include <chrono>
#include <cmath>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hots/hots.hpp"
#include "jeep/jeep.hpp"
#include "jeep/run_odometry.hpp"
#include "terra/search.hpp"
#include "ulc/calibrate/frame_range.hpp"
#include "ulc/calibrate/map_terra.hpp"
#include "ulc/calibrate/options.hpp"
#include "ulc/calibrate/pair_calibration.hpp"
#include "ulc/calibrate/stages.hpp"
#include "ulc/calibrate/terra_hypotheses.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

namespace calibrate_detail {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

/// How the stages after TERRA ended from one start, and whether the failure points at that
/// start (JEEP failed, or HOTS's cross links refused the extrinsic): the next TERRA hypothesis
/// is then worth a try.
struct StageOutcome {
  CalibrateStatus status = CalibrateStatus::ok;
  std::string reason;
  bool points_at_start = false;
};

inline TerraHypothesis hypothesis_entry(const terra::RotationCandidate& c, std::string source) {
  TerraHypothesis h;
  h.source = std::move(source);
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

/// One sentence for a failed HOTS, with what to do about it.
inline std::string hots_failure(const hots::RefineResult& h) {
  std::string why = std::string("HOTS: ") + hots::to_string(h.status) + ": " + h.reason;
  if (h.status == hots::RefineStatus::extrinsic_unconfirmed)
    why += "; " + std::to_string(h.statistics.cross_links_agreeing) + " of " +
           std::to_string(h.statistics.cross_links_attempted) +
           " agree: the extrinsic before HOTS is likely wrong (TERRA's rotation or the initial "
           "guess)";
  if (h.status == hots::RefineStatus::time_offset_untrusted)
    why +=
        "; a longer drive with turns and speed changes pins it down, and synchronised clocks "
        "are said so with time_offset_s = 0 (ulc calibrate --synced-clocks)";
  return why;
}

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Statistics of a TERRA search, in the report's form.
inline TerraReport terra_report(const terra::SearchResult& s, std::size_t frame_index,
                                std::size_t base_points, std::size_t target_points,
                                std::size_t lattice_size, double seconds) {
  TerraReport t;
  t.status = terra::to_string(s.status);
  t.reason = s.reason;
  t.rotation = s.rotation;
  t.distance = s.distance;
  t.mask_count = s.mask_count;
  t.frame_index = frame_index;
  t.base_points = base_points;
  t.target_points = target_points;
  t.lattice_size = lattice_size;
  t.stats = s.stats;
  t.seconds = seconds;
  return t;
}

/// The TERRA stage's path choice (CalibrateOptions::terra_source): fills r.terra (all but
/// seconds) and returns the kept search; `other` gets the search not kept when both ran.
template <class FramesA, class FramesB>
terra::SearchResult terra_stage(const FramesA& frames_a, const std::vector<double>& times_a,
                                const FramesB& frames_b, const std::vector<double>& times_b,
                                const CalibrateOptions& options, PairCalibration& r,
                                terra::SearchResult& other) {
  const CalibrateProgress& report = options.progress;
  const std::size_t i = options.frame_index;
  const terra::SearchParams& params = options.terra;
  const terra::Lattice lattice(params.lattice_size >= 2 ? params.lattice_size : 0);
  const std::size_t window =
      std::min(map_terra_detail::window_frames(times_a, i, options.terra_maps),
               map_terra_detail::window_frames(times_b, i, options.terra_maps));
  const TerraSource source = options.terra_source;
  const bool frames_first = source != TerraSource::maps;
  // Progress: the frame search is fast; when maps may follow they get most of the bar.
  const bool maps_possible =
      source == TerraSource::maps ||
      (source == TerraSource::automatic && window >= options.terra_maps_min_frames);
  const double frame_share = maps_possible ? 0.2 : 1.0;

  auto search_frames = [&] {
    terra::SearchParams p = params;
    if (report) p.progress = [&](double f) { report("terra", frame_share * f); };
    return params.lattice_size < 2 ? terra::estimate_rotation(frames_a[i], frames_b[i], p)
                                   : terra::estimate_rotation(lattice, frames_a[i], frames_b[i], p);
  };
  auto search_maps = [&] {
    const double from = frames_first ? frame_share : 0.0;
    std::function<void(double)> progress;
    if (report) progress = [&](double f) { report("terra", from + (1.0 - from) * f); };
    return params.lattice_size < 2 ? map_terra(frames_a, times_a, frames_b, times_b, i, params,
                                               options.terra_maps, progress)
                                   : map_terra(lattice, frames_a, times_a, frames_b, times_b, i,
                                               params, options.terra_maps, progress);
  };
  auto keep_frames = [&](const terra::SearchResult& s, std::string why) {
    r.terra = terra_report(s, i, traits::size(frames_a[i]), traits::size(frames_b[i]),
                           params.lattice_size, 0.0);
    r.terra->source = "frames";
    r.terra->source_reason = std::move(why);
    r.terra->frames_mask_count = s.mask_count;
    r.terra->frames_status = terra::to_string(s.status);
  };
  auto keep_maps = [&](const MapTerraResult& m, std::string why) {
    r.terra = terra_report(m.search, i, m.base.points, m.target.points, params.lattice_size, 0.0);
    r.terra->source = "maps";
    r.terra->source_reason = std::move(why);
    r.terra->base_map = m.base;
    r.terra->target_map = m.target;
  };

  if (source == TerraSource::maps) {
    const MapTerraResult m = search_maps();
    keep_maps(m, "terra_source = maps");
    return m.search;
  }
  const terra::SearchResult f = search_frames();
  if (source == TerraSource::frames) {
    keep_frames(f, "terra_source = frames");
    return f;
  }
  if (!maps_possible) {
    keep_frames(f, "automatic: " + std::to_string(window) + " frame(s) per LiDAR in the map " +
                       "window (maps need " + std::to_string(options.terra_maps_min_frames) + ")");
    return f;
  }
  if (f.ok() && f.mask_count >= options.terra_maps_below_mask) {
    keep_frames(f, "automatic: the frames overlap in " + std::to_string(f.mask_count) +
                       " cells (maps are tried below " +
                       std::to_string(options.terra_maps_below_mask) + ")");
    return f;
  }
  const MapTerraResult m = search_maps();
  const std::string frames_said =
      f.ok() ? "the frames overlap in only " + std::to_string(f.mask_count) + " cells"
             : std::string("the frame search failed (") + terra::to_string(f.status) + ")";
  if (m.ok() && (!f.ok() || m.search.mask_count > f.mask_count)) {
    keep_maps(m,
              "automatic: " + frames_said + "; the maps in " + std::to_string(m.search.mask_count));
    r.terra->frames_mask_count = f.mask_count;
    r.terra->frames_status = terra::to_string(f.status);
    other = f;
    return m.search;
  }
  keep_frames(f, "automatic: " + frames_said + ", but the map search " +
                     (m.ok() ? "overlaps less (" + std::to_string(m.search.mask_count) + " cells)"
                             : std::string("failed: ") + m.search.reason));
  r.terra->base_map = m.base;
  r.terra->target_map = m.target;
  other = m.search;
  return f;
}

inline JeepReport jeep_report(const jeep::JeepResult& j, const Isometry3d& initial,
                              double seconds) {
  JeepReport r;
  r.status = jeep::to_string(j.status);
  r.reason = j.reason;
  r.initial = initial;
  r.extrinsic = j.extrinsic;
  r.rounds = j.rounds;
  r.frame_pairs = j.pairs.size();
  r.calibration_status = ulc::to_string(j.calibration.status);
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
  r.second_look = j.second_look.ran;
  r.second_look_passed = j.second_look.passed;
  r.second_look_returned = j.second_look.returned;
  r.second_look_starts = j.second_look.starts;
  r.seconds = seconds;
  return r;
}

inline HotsReport hots_report(const jeep::OdometryResult& odo, const Isometry3d& initial,
                              double odometry_seconds) {
  HotsReport h;
  h.status = "not_run";
  h.odometry_status = jeep::to_string(odo.status);
  h.odometry_reason = odo.reason;
  h.frames_base = odo.poses_a.size();
  h.frames_target = odo.poses_b.size();
  h.odometry_failed_steps = odo.failed_steps;
  h.initial = initial;
  h.extrinsic = initial;
  h.odometry_seconds = odometry_seconds;
  return h;
}

inline void add_refine(HotsReport& h, const hots::RefineResult& r, double seconds) {
  h.status = hots::to_string(r.status);
  h.reason = r.reason;
  h.extrinsic = r.extrinsic;
  h.time_offset_s = r.time_offset_s;
  h.covariance_6x6 = r.covariance_6x6;
  h.statistics = r.statistics;
  h.spread_curve = r.spread_curve;
  h.seconds = seconds;
}

/// A JEEP that ran to its end without a usable extrinsic's verdict (rejected, or not settled)
/// with a finite extrinsic: HOTS can judge it (CalibrateOptions::hots_judges_jeep).
inline bool hots_can_judge(const jeep::JeepResult& j) {
  return (j.status == jeep::JeepStatus::rejected || j.status == jeep::JeepStatus::not_converged) &&
         j.extrinsic.matrix().allFinite();
}

/// The same from a JEEP stage's report (for callers that ran JEEP through calibrate_pair and
/// run HOTS themselves, as the benchmarks do).
inline bool hots_can_judge(const JeepReport& j) {
  return (j.status == jeep::to_string(jeep::JeepStatus::rejected) ||
          j.status == jeep::to_string(jeep::JeepStatus::not_converged)) &&
         j.extrinsic.matrix().allFinite();
}

/// Odometry gave a pose to every frame (possibly predicted ones): HOTS can start.
inline bool odometry_usable(const jeep::OdometryResult& odo) {
  return odo.ok() || odo.status == jeep::OdometryStatus::registration_failed;
}

}  // namespace calibrate_detail

/// Calibrates target LiDAR b against base LiDAR a (see the conventions at the top), reading the
/// frames in place through the point traits: every stage is instantiated for FramesA and
/// FramesB. ulc::calibrate_pair (ulc/calibrate.hpp) runs this once, on PointCloud<float>.
template <class FramesA, class FramesB>
PairCalibration calibrate_pair_in_place(const FramesA& frames_a, const std::vector<double>& times_a,
                                        const FramesB& frames_b,
                                        const std::vector<double>& times_b_own,
                                        const CalibrateOptions& options = {}) {
  using calibrate_detail::seconds_since;
  using calibrate_detail::StageOutcome;
  const auto start = std::chrono::steady_clock::now();
  PairCalibration r;
  r.stages = options.stages;
  auto finish = [&](CalibrateStatus status, std::string reason) {
    r.status = status;
    r.success = status == CalibrateStatus::ok;
    r.reason = std::move(reason);
    r.timing_s.total = seconds_since(start);
    return r;
  };
  auto report = [&](const std::string& stage, double fraction) {
    if (options.progress) options.progress(stage, fraction);
  };

  if (std::string why = check_stages(options.stages); !why.empty())
    return finish(CalibrateStatus::invalid_input, "stages: " + why);
  for (const Stage s : options.stages)
    if (!stage_available(s))
      return finish(CalibrateStatus::stage_not_available,
                    std::string("stage '") + to_string(s) + "' is not available yet");
  if (frames_a.size() != times_a.size() || frames_b.size() != times_b_own.size())
    return finish(CalibrateStatus::invalid_input, "frame and timestamp counts differ");
  if (options.time_offset_s && !std::isfinite(*options.time_offset_s))
    return finish(CalibrateStatus::invalid_input, "the known time offset is not finite");
  // A known clock offset: b's timestamps on a's clock, once, for every stage.
  std::vector<double> times_b_on_a;
  if (options.time_offset_s)
    for (const double t : times_b_own) times_b_on_a.push_back(t + *options.time_offset_s);
  const std::vector<double>& times_b = options.time_offset_s ? times_b_on_a : times_b_own;
  r.time_offset_s = options.time_offset_s.value_or(0.0);
  hots::RefineOptions hots_options = options.hots;
  if (options.time_offset_s) {
    hots_options.synchronise_time = false;
    hots_options.time_offset_s = 0.0;
    hots_options.sequence.estimate_time_offset = false;
  }
  const std::size_t i = options.frame_index;
  if (i >= frames_a.size() || i >= frames_b.size())
    return finish(CalibrateStatus::invalid_input,
                  "frame_index " + std::to_string(i) + " is past the end (base has " +
                      std::to_string(frames_a.size()) + " frames, target " +
                      std::to_string(frames_b.size()) + ")");
  const bool run_terra = has_stage(options.stages, Stage::terra);
  const bool run_jeep = has_stage(options.stages, Stage::jeep);
  const bool run_hots = has_stage(options.stages, Stage::hots);
  if (!run_terra && !options.initial)
    return finish(CalibrateStatus::initial_required,
                  "stages without terra need an initial extrinsic (TERRA is what finds one "
                  "without a guess)");
  if (!run_terra && !options.initial->matrix().allFinite())
    return finish(CalibrateStatus::invalid_input, "the initial extrinsic is not finite");

  const Isometry3d start_guess = run_terra ? Isometry3d::Identity() : *options.initial;
  r.T_base_target = start_guess;
  std::vector<terra::RotationCandidate> hypotheses;
  std::size_t first_fallback = 0;  // hypotheses from here on are the fallback's
  std::vector<std::string> sources;
  if (run_terra) {
    const auto t0 = std::chrono::steady_clock::now();
    terra::SearchResult other;
    const terra::SearchResult s =
        calibrate_detail::terra_stage(frames_a, times_a, frames_b, times_b, options, r, other);
    r.terra->seconds = seconds_since(t0);
    report("terra", 1.0);  // the map search may not have run after the frames' share
    r.timing_s.terra = r.terra->seconds;
    if (!s.ok())
      return finish(CalibrateStatus::terra_failed, std::string("TERRA: ") +
                                                       terra::to_string(s.status) + ": " +
                                                       s.reason + " (on " + r.terra->source + ")");
    const double separation =
        options.terra_hypothesis_separation_deg * calibrate_detail::kRadPerDeg;
    hypotheses =
        terra_hypotheses(s, std::max<std::size_t>(1, options.terra_hypotheses), separation);
    first_fallback = hypotheses.size();
    sources.assign(hypotheses.size(), r.terra->source);
    const std::string other_source = r.terra->source == "maps" ? "frames" : "maps";
    for (const terra::SearchResult* search : {&s, static_cast<const terra::SearchResult*>(&other)})
      for (const auto& c : fallback_hypotheses(
               *search, hypotheses,
               options.terra_fallback_hypotheses - (hypotheses.size() - first_fallback),
               separation)) {
        hypotheses.push_back(c);
        sources.push_back(search == &s ? r.terra->source : other_source);
      }
  }
  if (!run_jeep && !run_hots) {
    r.T_base_target.linear() = hypotheses.front().rotation;
    r.terra->hypotheses.push_back(
        calibrate_detail::hypothesis_entry(hypotheses.front(), sources.front()));
    r.terra->hypotheses.back().outcome = "ok";
    return finish(CalibrateStatus::ok, "");
  }

  // JEEP and odometry + HOTS from `start` on the frames from i on, into `out`.
  const std::size_t frames_left = std::min(frames_a.size(), frames_b.size()) - i;
  const std::vector<double> ta = times_from(times_a, i), tb = times_from(times_b, i);
  // HOTS can judge a start: it runs, on a moving rig.
  const bool can_verify = run_hots && frames_left >= options.hots_min_frames;
  auto run_from = [&](const Isometry3d& start, const std::string& label, bool hots_may_judge,
                      PairCalibration& out) -> StageOutcome {
    auto stage = [&](const char* name) { return label.empty() ? name : name + label; };
    std::string jeep_failure;  // set when JEEP failed and HOTS judges its extrinsic
    Isometry3d C = start;
    out.T_base_target = C;
    const FrameRange<FramesA> view_a(frames_a, i);
    const FrameRange<FramesB> view_b(frames_b, i);
    auto progress_of = [&](const std::string& name) {
      jeep::ProgressFn progress;
      if (options.progress)
        progress = [&, name](std::size_t done, std::size_t total) {
          report(name, total ? static_cast<double>(done) / static_cast<double>(total) : 1.0);
        };
      return progress;
    };
    if (run_jeep) {
      const auto t0 = std::chrono::steady_clock::now();
      report(stage("jeep"), 0.0);
      const jeep::JeepResult j =
          jeep::run_jeep(view_a, ta, view_b, tb, C, options.jeep, progress_of(stage("jeep")));
      out.jeep = calibrate_detail::jeep_report(j, C, seconds_since(t0));
      out.timing_s.jeep = out.jeep->seconds;
      report(stage("jeep"), 1.0);
      if (!j.ok()) {
        jeep_failure = std::string("JEEP: ") + jeep::to_string(j.status) + ": " + j.reason;
        out.jeep->judged_by_hots = hots_may_judge && options.hots_judges_jeep && can_verify &&
                                   calibrate_detail::hots_can_judge(j);
        if (!out.jeep->judged_by_hots) return {CalibrateStatus::jeep_failed, jeep_failure, true};
      }
      C = j.extrinsic;
      if (j.ok()) out.T_base_target = C;
    }
    // A failed JEEP judged by HOTS: HOTS's refusal is JEEP's failure; its success overrules it.
    auto failed = [&](CalibrateStatus status, std::string why, bool points_at_start) {
      if (jeep_failure.empty()) return StageOutcome{status, std::move(why), points_at_start};
      return StageOutcome{CalibrateStatus::jeep_failed,
                          jeep_failure + " (HOTS, run from its extrinsic to judge it: " + why + ")",
                          points_at_start};
    };
    if (!run_hots) return {CalibrateStatus::ok, "", false};
    if (frames_left < options.hots_min_frames && (run_terra || run_jeep)) {
      out.hots = HotsReport{};
      out.hots->status = "skipped";
      out.hots->reason = "only " + std::to_string(frames_left) + " frame(s) per LiDAR from frame " +
                         std::to_string(i) + " (HOTS needs " +
                         std::to_string(options.hots_min_frames) +
                         " of a moving rig); the extrinsic is the previous stage's";
      out.hots->initial = out.hots->extrinsic = C;
      return {CalibrateStatus::ok, "", false};
    }
    auto t0 = std::chrono::steady_clock::now();
    report(stage("odometry"), 0.0);
    const jeep::OdometryResult odo = jeep::run_odometry(view_a, ta, view_b, tb, C, options.odometry,
                                                        progress_of(stage("odometry")));
    out.timing_s.odometry = seconds_since(t0);
    out.hots = calibrate_detail::hots_report(odo, C, out.timing_s.odometry);
    if (!calibrate_detail::odometry_usable(odo))
      return failed(
          CalibrateStatus::hots_failed,
          std::string("HOTS: odometry: ") + jeep::to_string(odo.status) + ": " + odo.reason,
          !jeep_failure.empty());
    report(stage("odometry"), 1.0);
    report(stage("hots"), 0.0);
    t0 = std::chrono::steady_clock::now();
    const hots::RefineResult h =
        hots::refine(view_a, ta, odo.poses_a, view_b, tb, odo.poses_b, C, hots_options);
    out.timing_s.hots = seconds_since(t0);
    calibrate_detail::add_refine(*out.hots, h, out.timing_s.hots);
    out.hots->time_offset_s += out.time_offset_s;  // back to b's own clock
    if (!h.ok())
      return failed(CalibrateStatus::hots_failed, calibrate_detail::hots_failure(h),
                    h.status == hots::RefineStatus::extrinsic_unconfirmed || !jeep_failure.empty());
    report(stage("hots"), 1.0);
    out.T_base_target = h.extrinsic;
    out.time_offset_s += h.time_offset_s;
    out.covariance_6x6 = h.covariance_6x6;
    return {CalibrateStatus::ok, "", false};
  };

  if (!run_terra) {
    const StageOutcome o = run_from(start_guess, "", true, r);
    return finish(o.status, o.reason);
  }

  // TERRA's hypotheses in turn (terra_hypotheses.hpp): when what followed the best one points
  // at the rotation (JEEP failed, or HOTS's cross links disagree) and HOTS can judge the next
  // one, the next one runs. The first success wins.
  PairCalibration first;
  StageOutcome first_outcome;
  for (std::size_t k = 0; k < hypotheses.size(); ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    Isometry3d start = Isometry3d::Identity();
    start.linear() = hypotheses[k].rotation;
    TerraHypothesis entry = calibrate_detail::hypothesis_entry(hypotheses[k], sources[k]);
    const std::string label = k == 0 ? "" : " (hypothesis " + std::to_string(k + 1) + ")";
    PairCalibration attempt;
    attempt.time_offset_s = r.time_offset_s;
    const StageOutcome o = run_from(start, label, k < first_fallback, attempt);
    entry.outcome = o.status == CalibrateStatus::ok
                        ? std::string("ok")
                        : std::string(to_string(o.status)) + ": " + o.reason;
    entry.seconds = seconds_since(t0);
    r.terra->hypotheses.push_back(entry);
    calibrate_detail::add_timings(r.timing_s, attempt.timing_s);
    // A failure that does not point at the rotation (the views confirmed it, the clocks'
    // offset is untrusted, say) is this hypothesis's own answer; so is the best's when no other
    // can be judged.
    const bool next_worth_it = can_verify && o.points_at_start && k + 1 < hypotheses.size();
    if (o.status == CalibrateStatus::ok || (!next_worth_it && (k == 0 || !o.points_at_start))) {
      calibrate_detail::take_stages(r, attempt);
      r.terra->hypothesis_used = k;
      return finish(o.status, o.reason);
    }
    if (k == 0) {
      first = std::move(attempt);
      first_outcome = o;
    }
  }
  // None succeeded: the best hypothesis's outcome, and what the others said.
  calibrate_detail::take_stages(r, first);
  r.terra->hypothesis_used = 0;
  return finish(first_outcome.status,
                first_outcome.reason + "; TERRA's next " +
                    std::to_string(r.terra->hypotheses.size() - 1) +
                    " hypotheses were not confirmed either (stages.terra.hypotheses)");
}

}  // namespace ulc
