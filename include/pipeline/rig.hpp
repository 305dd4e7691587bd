// A rig of N LiDARs, one of them the base: every other LiDAR (a target) calibrated against the
// base, routed through another LiDAR when the direct attempt fails, and the cycles between
// targets closed to show how well the extrinsics agree.
//
// Conventions this header owns:
//   - Input: RigLidar views (name, frames, timestamps, optional guess); the frames and times
//     must outlive the call. Targets are every LiDAR but the base, reported in input order.
//     Names must be unique and not empty (the result file keys on them).
//   - Direct: calibrate_pair(base, target, options.pair) for every target. options.pair.initial
//     is ignored: each LiDAR carries its own guess, RigLidar::initial = T_base_lidar (needed
//     only when options.pair.stages skip terra). With the base's own odometry (tuning.hots_odometry
//     base, or automatic choosing it: the choice looks at the base alone), the base's own
//     odometry and HOTS's preparation of its frames are done once, by the first target that
//     needs them, and given to the others: each direct result is the one calibrate_pair gives
//     alone, bit for bit.
//   - Routing (options.route): a target whose direct attempt failed is calibrated through a
//     LiDAR v whose direct attempt succeeded: calibrate_pair(v, target, options.pair), then
//     T_base_target = T_base_v * T_v_target and time_offset = offset_base_v + offset_v_target
//     (t_base = t_v + o1, t_v = t_target + o2). One hop only: a routed target is never a via.
//     Candidates are tried in a fixed order of quality: JEEP's acceptance overlap of v's direct
//     calibration (higher first; 0 when JEEP did not run), then name, then input index; the
//     first that succeeds is kept. Without terra, the routed guess is T_base_v^-1 *
//     RigLidar::initial of the target. A routed result has no covariance (it is not the
//     composition's, and inventing one would be worse than none).
//     Routing happens only when the direct attempt FAILED: a direct result that passed JEEP's
//     acceptance is not second-guessed (the acceptance rule is the honest overlap test we have).
//   - Cycles (options.cycles): for every pair i < j (input order) of calibrated targets,
//     calibrate_pair(i, j) with options.cycle_stages gives T_i_j; the closure error of the cycle
//     base -> i -> j -> base is E = T_base_i * T_i_j * T_base_j^-1 (identity when everything
//     agrees): rotation_deg = angle of E, translation_m = |translation of E|. Without terra in
//     cycle_stages, the guess is T_base_i^-1 * T_base_j (so the cycle only tests refinement).
//     When both targets' clock offsets are known (given, or estimated by HOTS), the i -> j
//     calibration is given their difference, so it need not estimate one (pipeline/vouch.hpp).
//     A pair where one target was routed through the other is skipped: that cycle is the route
//     itself and closes by construction, which would look like evidence and is none.
//     At most options.max_cycles cycles, the first ones in that order.
//   - Progress: options.pair.progress(prefix + stage, fraction) with prefix "<target> " for a
//     direct attempt, "<target> via <v> " for a routed one, "cycle <i>-<j> " for a cycle.
//   - Sequential over pairs (each pair's stages are parallel and deterministic inside), so the
//     whole result is the same for any thread count. Nothing here throws, exits or prints; it
//     compiles with -fno-exceptions.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/calibrate.hpp"
#include "pipeline/pair_calibration.hpp"
#include "pipeline/stages.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// One LiDAR of the rig: a view of its frames and timestamps (not owned).
template <class Frames>
struct RigLidar {
  std::string name;
  const Frames* frames = nullptr;
  const std::vector<double>* times = nullptr;  ///< one per frame, seconds, own clock
  std::optional<Isometry3d> initial;           ///< T_base_lidar guess, used when terra does not run
};

struct RigOptions {
  CalibrateOptions pair;  ///< every direct and routed calibration (initial: see RigLidar)
  bool route = true;      ///< calibrate failed targets through a calibrated LiDAR
  bool cycles = true;     ///< close the cycles base -> i -> j -> base
  std::vector<Stage> cycle_stages{Stage::terra, Stage::jeep};  ///< the cheap i -> j check
  std::size_t max_cycles = std::numeric_limits<std::size_t>::max();
};

/// A route that was tried for a target and did not work.
struct RigRouteAttempt {
  std::size_t via = 0;  ///< input index of the LiDAR it went through
  std::string via_name;
  CalibrateStatus status = CalibrateStatus::invalid_input;
  std::string reason;
};

struct RigTarget {
  std::size_t lidar = 0;  ///< input index
  std::string name;
  PairCalibration direct;  ///< the attempt against the base
  /// When routed: the LiDAR it went through, and the via -> target calibration.
  std::optional<std::size_t> via;
  std::string via_name;
  std::optional<PairCalibration> via_pair;
  std::vector<RigRouteAttempt> failed_routes;  ///< in the order tried
  /// What to report: the direct calibration, or for a routed target the via -> target one with
  /// T_base_target and time_offset_s chained from the base, no covariance, timing_s.total
  /// including the direct attempt, and a reason naming the route and the direct failure.
  PairCalibration result;

  bool ok() const { return result.success; }
  bool routed() const { return via.has_value(); }
};

struct RigCycle {
  std::size_t i = 0, j = 0;  ///< input indices: the cycle base -> i -> j -> base
  std::string name_i, name_j;
  PairCalibration pair;  ///< i -> j with cycle_stages: T_i_j
  /// Closure errors, only when the i -> j calibration succeeded.
  std::optional<double> rotation_deg, translation_m;

  bool ok() const { return pair.success; }
};

enum class RigStatus {
  ok,              ///< every target calibrated (directly or routed)
  invalid_input,   ///< bad base index, missing frames, empty or repeated names
  targets_failed,  ///< at least one target could not be calibrated
};

inline const char* to_string(RigStatus s) {
  switch (s) {
    case RigStatus::ok:
      return "ok";
    case RigStatus::invalid_input:
      return "invalid_input";
    default:
      return "targets_failed";
  }
}

struct RigCalibration {
  RigStatus status = RigStatus::invalid_input;
  std::string reason;
  std::size_t base = 0;  ///< input index
  std::string base_name;
  std::vector<RigTarget> targets;  ///< every LiDAR but the base, input order
  std::vector<RigCycle> cycles;
  double seconds = 0.0;

  bool ok() const { return status == RigStatus::ok; }
};

namespace rig_detail {

/// options.pair with its progress prefixed and its guess set; without the base's odometry
/// (a route or a cycle has another base).
inline CalibrateOptions pair_options(const CalibrateOptions& base, const std::string& prefix,
                                     std::optional<Isometry3d> initial) {
  CalibrateOptions o = base;
  o.initial = std::move(initial);
  o.base_work = {};
  if (base.progress) {
    const CalibrateProgress inner = base.progress;
    o.progress = [inner, prefix](const std::string& stage, double f) { inner(prefix + stage, f); };
  }
  return o;
}

template <class Frames>
PairCalibration calibrate(const RigLidar<Frames>& a, const RigLidar<Frames>& b,
                          const CalibrateOptions& options) {
  return calibrate_pair(*a.frames, *a.times, *b.frames, *b.times, options);
}

/// The JEEP acceptance overlap of a direct calibration (0 when JEEP did not run).
inline double overlap_of(const PairCalibration& c) {
  return c.jeep ? c.jeep->overlap : 0.0;
}

/// The routed target's report: the via calibration chained from the base.
inline PairCalibration chained(const PairCalibration& base_via, const PairCalibration& via_target,
                               const PairCalibration& direct, const std::string& via_name) {
  PairCalibration r = via_target;
  r.T_base_target = base_via.T_base_target * via_target.T_base_target;
  r.time_offset_s = base_via.time_offset_s + via_target.time_offset_s;
  r.covariance_6x6.reset();
  r.timing_s.total += direct.timing_s.total;
  r.reason = "calibrated through " + via_name + "; the direct attempt failed: " + direct.reason;
  return r;
}

template <class Frames>
std::string check_input(const std::vector<RigLidar<Frames>>& lidars, std::size_t base) {
  if (lidars.size() < 2) return "a rig needs a base and at least one target";
  if (base >= lidars.size())
    return "base index " + std::to_string(base) + " is past the end (" +
           std::to_string(lidars.size()) + " LiDARs)";
  for (std::size_t k = 0; k < lidars.size(); ++k) {
    const RigLidar<Frames>& l = lidars[k];
    if (l.name.empty()) return "LiDAR " + std::to_string(k) + " has no name";
    if (!l.frames || !l.times) return "LiDAR '" + l.name + "' has no frames or no timestamps";
    for (std::size_t m = 0; m < k; ++m)
      if (lidars[m].name == l.name) return "two LiDARs are named '" + l.name + "'";
  }
  return {};
}

/// Every target against the base, directly. The base's own odometry, run by the first target
/// whose HOTS needed it, and HOTS's preparation of its frames are handed to the next ones
/// (CalibrateOptions::base_work).
template <class Frames>
void calibrate_directly(const std::vector<RigLidar<Frames>>& lidars, std::size_t base,
                        const RigOptions& options, RigCalibration& rig) {
  BaseWork shared = options.pair.base_work;
  for (std::size_t k = 0; k < lidars.size(); ++k) {
    if (k == base) continue;
    RigTarget t;
    t.lidar = k;
    t.name = lidars[k].name;
    CalibrateOptions o = pair_options(options.pair, t.name + " ", lidars[k].initial);
    o.base_work = shared;
    t.direct = calibrate(lidars[base], lidars[k], o);
    if (!shared.odometry) shared.odometry = t.direct.base_work.odometry;
    if (!shared.hots) shared.hots = t.direct.base_work.hots;
    if (!shared.stillness) shared.stillness = t.direct.base_work.stillness;
    t.result = t.direct;
    rig.targets.push_back(std::move(t));
  }
  // The base's prepared frames are large (hundreds of MB on a long drive): not kept in results.
  for (RigTarget& t : rig.targets) t.direct.base_work.hots = t.result.base_work.hots = nullptr;
}

/// The targets calibrated directly, best first (JEEP's overlap, then the name).
inline std::vector<std::size_t> route_candidates(const std::vector<RigTarget>& targets) {
  std::vector<std::size_t> candidates;
  for (std::size_t n = 0; n < targets.size(); ++n)
    if (targets[n].direct.success) candidates.push_back(n);
  std::stable_sort(candidates.begin(), candidates.end(), [&](std::size_t x, std::size_t y) {
    const double ox = overlap_of(targets[x].direct);
    const double oy = overlap_of(targets[y].direct);
    if (ox != oy) return ox > oy;
    return targets[x].name < targets[y].name;
  });
  return candidates;
}

/// A failed target through each candidate in turn until one calibrates it.
template <class Frames>
void route(const std::vector<RigLidar<Frames>>& lidars, const std::vector<std::size_t>& candidates,
           const RigOptions& options, const std::vector<RigTarget>& targets, RigTarget& t) {
  for (const std::size_t n : candidates) {
    const RigTarget& v = targets[n];
    std::optional<Isometry3d> guess;
    if (lidars[t.lidar].initial)
      guess = v.direct.T_base_target.inverse() * *lidars[t.lidar].initial;
    const PairCalibration c =
        calibrate(lidars[v.lidar], lidars[t.lidar],
                  pair_options(options.pair, t.name + " via " + v.name + " ", guess));
    if (!c.success) {
      t.failed_routes.push_back({v.lidar, v.name, c.status, c.reason});
      continue;
    }
    t.via = v.lidar;
    t.via_name = v.name;
    t.via_pair = c;
    t.result = chained(v.direct, c, t.direct, v.name);
    return;
  }
  if (t.failed_routes.empty()) return;
  t.result.reason += "; no route worked either:";
  for (const RigRouteAttempt& a : t.failed_routes)
    t.result.reason += std::string(" through ") + a.via_name + ": " + to_string(a.status) +
                       (&a == &t.failed_routes.back() ? "" : ",");
}

/// The cycle base -> i -> j -> base of two calibrated targets: i against j from the chain's
/// prediction, and how far the loop is from closing.
template <class Frames>
RigCycle close_cycle(const std::vector<RigLidar<Frames>>& lidars, const RigTarget& ti,
                     const RigTarget& tj, const RigOptions& options) {
  CalibrateOptions o = pair_options(options.pair, "cycle " + ti.name + "-" + tj.name + " ",
                                    ti.result.T_base_target.inverse() * tj.result.T_base_target);
  o.stages = options.cycle_stages;
  // Both clocks known against the base (given or estimated by HOTS): t_i = t_j + (o_j - o_i).
  auto known = [](const PairCalibration& p) {
    return p.clock && p.clock->source != ClockSource::not_estimated;
  };
  if (known(ti.result) && known(tj.result))
    o.time_offset_s = tj.result.time_offset_s - ti.result.time_offset_s;
  RigCycle c;
  c.i = ti.lidar;
  c.j = tj.lidar;
  c.name_i = ti.name;
  c.name_j = tj.name;
  c.pair = calibrate(lidars[ti.lidar], lidars[tj.lidar], o);
  if (c.pair.success) {
    const Isometry3d E =
        ti.result.T_base_target * c.pair.T_base_target * tj.result.T_base_target.inverse();
    const PoseError e = pose_error(Isometry3d(Isometry3d::Identity()), E);
    c.rotation_deg = e.rotation_deg;
    c.translation_m = e.translation_m;
  }
  return c;
}

/// Every pair of calibrated targets not routed through each other, up to max_cycles.
template <class Frames>
void check_cycles(const std::vector<RigLidar<Frames>>& lidars, const RigOptions& options,
                  RigCalibration& rig) {
  for (std::size_t x = 0; x < rig.targets.size(); ++x) {
    for (std::size_t y = x + 1; y < rig.targets.size(); ++y) {
      const RigTarget& ti = rig.targets[x];
      const RigTarget& tj = rig.targets[y];
      if (!ti.ok() || !tj.ok()) continue;
      // A target routed through the other IS this cycle: it closes by construction.
      if (ti.via == tj.lidar || tj.via == ti.lidar) continue;
      if (rig.cycles.size() >= options.max_cycles) break;
      rig.cycles.push_back(close_cycle(lidars, ti, tj, options));
    }
  }
}

/// ok when every target calibrated, else which did not.
inline void judge_rig(RigCalibration& rig) {
  bool all = true;
  for (const RigTarget& t : rig.targets) all = all && t.ok();
  rig.status = all ? RigStatus::ok : RigStatus::targets_failed;
  if (all) return;
  rig.reason = "not calibrated:";
  for (const RigTarget& t : rig.targets)
    if (!t.ok()) rig.reason += " " + t.name;
}

}  // namespace rig_detail

/// Calibrates every LiDAR of `lidars` but `base` against the base (see the conventions above).
template <class Frames>
RigCalibration calibrate_rig(const std::vector<RigLidar<Frames>>& lidars, std::size_t base,
                             const RigOptions& options = {}) {
  const auto start = std::chrono::steady_clock::now();
  RigCalibration rig;
  rig.base = base;
  if (std::string why = rig_detail::check_input(lidars, base); !why.empty()) {
    rig.reason = std::move(why);
    return rig;
  }
  rig.base_name = lidars[base].name;
  rig_detail::calibrate_directly(lidars, base, options, rig);
  if (options.route) {
    // Candidates fixed before any routing.
    const std::vector<std::size_t> candidates = rig_detail::route_candidates(rig.targets);
    for (RigTarget& t : rig.targets)
      if (!t.direct.success) rig_detail::route(lidars, candidates, options, rig.targets, t);
  }
  if (options.cycles) rig_detail::check_cycles(lidars, options, rig);
  rig_detail::judge_rig(rig);
  rig.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return rig;
}

}  // namespace ulc
