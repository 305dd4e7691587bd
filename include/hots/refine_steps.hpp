// The steps of hots::refine (hots.hpp, whose header comment holds the conventions), each a
// function on the state the call builds: inputs checked, frames prepared, hierarchies, cross
// links, the pose graph and its passes, the whole-sequence step, the poses out.
// The state: refine_state.hpp; the inputs and frames: refine_prepare.hpp; the pose graph:
// refine_graph.hpp.
#pragma once

#include <chrono>
#include <cstddef>
#include <vector>

#include "hots/boundary_bridges.hpp"
#include "hots/boundary_links.hpp"
#include "hots/cross_links.hpp"
#include "hots/hierarchy.hpp"
#include "hots/options.hpp"
#include "hots/refine_graph.hpp"
#include "hots/refine_prepare.hpp"
#include "hots/refine_state.hpp"
#include "hots/refine_statistics.hpp"
#include "hots/sequence_extrinsic.hpp"
#include "hots/sparse_lm.hpp"
#include "hots/time_sync.hpp"
#include "ulc/core/mahalanobis.hpp"

namespace hots {

namespace hots_detail {

/// How many kept links must agree for the trust rule to confirm the extrinsic.
inline double agreeing_needed(const RefineStatistics& st, const RefineOptions& options) {
  return std::max(static_cast<double>(options.min_cross_links),
                  options.min_cross_link_ratio * static_cast<double>(st.cross_links_attempted));
}

/// The trust rule on the cross links (see the conventions): enough kept links agree, too few
/// do, or none was kept (too little overlap to judge: HOTS has no evidence for the extrinsic
/// and refuses it too). No attempt: nothing to judge.
inline LinkVerdict judge_links(const RefineStatistics& st, const RefineOptions& options) {
  if (!(options.min_cross_link_ratio > 0.0) || st.cross_links_attempted == 0)
    return LinkVerdict::not_judged;
  if (st.cross_links == 0) return LinkVerdict::too_little_overlap;
  return static_cast<double>(st.cross_links_agreeing) >= agreeing_needed(st, options)
             ? LinkVerdict::kept_links_agree
             : LinkVerdict::kept_links_refute;
}

/// Whether the links deserve a second look within a's reach (CrossLinkOptions::
/// second_look_within_reach): they did not confirm the extrinsic, and fewer were kept than
/// would have to agree, so the plain ratio could not have judged it either way. Links kept
/// and moving away from their start are a verdict, and keep it.
inline bool second_look_within_reach(const RefineStatistics& st, const RefineOptions& options) {
  return options.links.second_look_within_reach && !confirms(st.link_verdict) &&
         static_cast<double>(st.cross_links) < agreeing_needed(st, options);
}

/// The kept links and their counts into `st`, then the trust rule's verdict on them.
template <typename S>
void judge_selected_links(RefineState<S>& s, const std::vector<LinkRegistration>& registrations,
                          bool within_reach, const RefineOptions& options, RefineStatistics& st) {
  CrossLinkStats link_stats;
  s.links = select_links(registrations, options.links, within_reach, link_stats);
  st.cross_links = s.links.size();
  st.cross_links_attempted = link_stats.attempted;
  st.cross_links_agreeing = link_stats.agreeing;
  st.cross_links_converged = link_stats.converged;
  st.cross_links_weak = link_stats.weak;
  st.cross_links_weak_agreeing = link_stats.weak_agreeing;
  st.cross_link_inlier_ratio_median = link_stats.inlier_ratio_median;
  st.cross_link_records = std::move(link_stats.records);
  st.links_judged_within_reach = within_reach;
  st.link_verdict = judge_links(st, options);
}

/// Why the cross links did not confirm the extrinsic. Kept links moving away from their
/// prediction say it is wrong. None kept (every registration failed or left too few of b's
/// points on a's surfaces, CrossLinkOptions::min_inlier_ratio) says the views overlap too little
/// to judge: 64-tele seed 2's right extrinsic kept none of 90, its links' inlier ratios
/// 0.12-0.26, the Tele's far points beyond the HDL-64E's frames and submaps
/// (docs/experiments/tele_cross_links.md).
inline const char* unconfirmed_reason(LinkVerdict verdict) {
  if (verdict == LinkVerdict::kept_links_refute)
    return "too few of the cross links (b's submaps registered to a's through the extrinsic) "
           "agree with it: the two LiDARs' views do not confirm the extrinsic (statistics: "
           "cross_links_agreeing of cross_links_attempted)";
  return "none of the cross links (b's submaps registered to a's through the extrinsic) kept "
         "enough of b's points on a's surfaces: the two LiDARs' views overlap too little for "
         "HOTS to judge the extrinsic, right or wrong (statistics: cross_links of "
         "cross_links_attempted)";
}

/// Each LiDAR's hierarchy of windows (hierarchy.hpp) and bridges across its top-layer
/// boundaries (boundary_bridges.hpp); the world poses become the hierarchy's.
/// progress gets the fraction done, a's frames first (the work grows with the frames).
template <typename S>
void build_hierarchies(RefineState<S>& s, const RefineOptions& options, RefineStatistics& st,
                       const ulc::StepProgress& progress) {
  const double share_a = s.a.reused ? 0.0 : share_of_a(s.a.frames.size(), s.b.frames.size());
  for (RefineLidar<S>* l : {&s.a, &s.b}) {
    if (l->reused) continue;
    const bool parts = options.hierarchy.sweep_parts > 1;
    const bool is_a = l == &s.a;
    l->hierarchy =
        build_hierarchy(l->frames, l->world, options.hierarchy, parts ? &l->sweeps : nullptr,
                        ulc::progress_within(progress, is_a ? 0.0 : share_a, is_a ? share_a : 1.0));
    if (options.boundary_bridges)
      l->bridges = boundary_bridges(l->hierarchy, l->frames, options.hierarchy);
    l->world = l->hierarchy.poses;
  }
  st.hierarchy_seconds = lap(s.clock);
  st.windows =
      s.a.hierarchy.windows + s.b.hierarchy.windows + s.a.bridges.windows + s.b.bridges.windows;
  st.failed_windows = s.a.hierarchy.failed_windows + s.b.hierarchy.failed_windows;
  st.planes = s.a.hierarchy.planes + s.b.hierarchy.planes + s.a.bridges.planes + s.b.bridges.planes;
}

/// The cross links between the LiDARs (cross_links.hpp); false when too few agree with the
/// extrinsic (see judge_links), after a second look within a's reach when too few were kept to
/// judge (second_look_within_reach). Then each LiDAR's top-layer boundaries registered
/// (boundary_links.hpp) (statistics: cross_links).
/// progress gets the fraction of cross links registered.
template <typename S>
bool link_lidars(RefineState<S>& s, double time_offset_s, const RefineOptions& options,
                 RefineStatistics& st, const ulc::StepProgress& progress) {
  const std::vector<LinkRegistration> registrations = cross_link_registrations(
      s.a.hierarchy, s.a.frames, s.a.times, s.a.world, s.b.hierarchy, s.b.frames, s.b.times,
      s.b.world, time_offset_s, options.links, progress);
  // Decided here, before the graph, the synchronisation and the sequence step: their work
  // would rest on an extrinsic the views refuse (and a caller trying several is spared it).
  judge_selected_links(s, registrations, false, options, st);
  if (second_look_within_reach(st, options))
    judge_selected_links(s, registrations, true, options, st);
  if (!confirms(st.link_verdict)) return false;
  if (options.boundary_registration)
    for (RefineLidar<S>* l : {&s.a, &s.b})
      l->boundaries = boundary_links(l->hierarchy, l->frames, l->world, options.links,
                                     options.boundary_radius_m, &l->bridges.bridged);
  st.links_seconds = lap(s.clock);
  return true;
}

/// The time synchronisation on the graph's poses (time_sync.hpp); its extrinsic becomes C's
/// value for the next pass. False when it failed (result.reason says why).
template <typename S>
bool synchronise(RefineState<S>& s, const RefineOptions& options, RefineResult& result) {
  RefineStatistics& st = result.statistics;
  TimeSyncOptions ts = options.time_sync;
  ts.centre_s = options.time_offset_s;
  const TimeSyncResult sync =
      time_sync(s.a.times, graph_poses(s, s.a), s.b.times, graph_poses(s, s.b), ts);
  st.sync_seconds += lap(s.clock);
  if (!sync.ok()) {
    result.reason = sync.reason;
    return false;
  }
  result.time_offset_s = sync.time_offset_s;
  result.extrinsic = sync.extrinsic;
  result.covariance_6x6 = sync.covariance;
  result.spread_curve = sync.curve;
  st.time_sync_spread = sync.spread;
  st.time_sync_pairs = sync.pairs;
  st.sync_extrinsic = sync.extrinsic;
  st.sync_time_offset_s = sync.time_offset_s;
  st.sync_significant = sync.significant;
  s.graph.variables[s.extrinsic_var] = sync.extrinsic;
  return true;
}

/// options.passes rounds of: ties at the current offset, the graph solved, then the time
/// synchronisation (without it, one pass and the graph's marginal covariance of C). ok, or
/// graph_failed / time_sync_failed with result.reason set.
template <typename S>
RefineStatus solve_passes(RefineState<S>& s, const RefineOptions& options, RefineResult& result) {
  RefineStatistics& st = result.statistics;
  for (int pass = 0; pass < options.passes; ++pass) {
    set_ties(s, result.time_offset_s, options, st);
    lap(s.clock);
    const SparseLmResult lm = solve_pose_graph(s.graph, options.solver);
    st.graph_seconds += lap(s.clock);
    if (pass == 0) st.graph_initial_cost = lm.initial_cost;
    st.graph_cost = lm.cost;
    st.graph_iterations += lm.iterations;
    if (!(lm.ok() || lm.status == SparseLmStatus::not_converged)) {
      result.reason = lm.reason;
      return RefineStatus::graph_failed;
    }
    st.graph_extrinsic = s.graph.variables[s.extrinsic_var];
    result.extrinsic = st.graph_extrinsic;
    if (!options.synchronise_time) {
      result.covariance_6x6 = marginal_covariance(s.graph, s.extrinsic_var, options.solver.grain);
      return RefineStatus::ok;
    }
    if (!synchronise(s, options, result)) return RefineStatus::time_sync_failed;
  }
  return RefineStatus::ok;
}

/// The whole-sequence step (sequence_extrinsic.hpp) from the current extrinsic and offset.
/// The whole-sequence step again, from the extrinsic refine started from (JEEP's, or the
/// caller's) when that start lies beyond the 3-sigma ellipsoid of the step's answer C (the
/// covariance already carrying the move term): log(C_rerun C^-1), zero when the start is
/// inside or the rerun failed. A third model of the same data (hots.hpp, covariance): its
/// cost can be flat along a direction over tens of centimetres, where a run rests near wherever
/// it began and its jackknife, the local curvature, sees nothing (bench_covariance, side-bpearl
/// seed 5, 10 s: from the graph's C the step ended 29 cm off along the drive with sigma 2.6 cm;
/// from JEEP's, 0.3 cm off, it ended 6.3 cm off; the two costs 0.4 % apart).
/// The rerun shares the step's prepared submaps and frames and solves as the step ended, with
/// the offset free only when the step refined it (SequenceStep::solve_extrinsic).
template <typename S>
Vec6d rerun_from_start(const RefineState<S>& s, SequenceStep<S>& step, const Mat6d& covariance,
                       RefineResult& result) {
  const Vec6d away = ulc::se3_log(Isometry3d(s.start * result.extrinsic.inverse()));
  if (ulc::within_three_sigma(away, covariance)) return Vec6d::Zero();
  SequenceExtrinsicResult& rerun = result.statistics.sequence_rerun;
  rerun = step.solve_extrinsic(s.start, result.statistics.sequence.time_offset_refined);
  if (!rerun.ok()) return Vec6d::Zero();
  return ulc::se3_log(Isometry3d(rerun.extrinsic * result.extrinsic.inverse()));
}

/// False when it failed (result.reason says why). progress gets the step's fraction done.
template <typename S>
bool sequence_step(RefineState<S>& s, const RefineOptions& options, RefineResult& result,
                   const ulc::StepProgress& progress) {
  RefineStatistics& st = result.statistics;
  // The joint dt is refined only where the synchronisation found an offset at all: its
  // significance test is what keeps a synchronised rig at exactly zero.
  SequenceExtrinsicOptions so = options.sequence;
  so.estimate_time_offset = so.estimate_time_offset && st.sync_significant;
  // Without synchronisation the offset is the caller's (known clocks): nothing to check.
  so.check_time_offset = so.check_time_offset && options.synchronise_time;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Isometry3d> world_a = graph_poses(s, s.a);  // read by the step and its rerun
  SequenceStep<S> step(s.a.hierarchy, s.a.frames, s.a.times, world_a, s.b.frames, s.b.times,
                       result.time_offset_s, so, progress);
  st.sequence = step.solve(result.extrinsic, progress);
  if (!st.sequence.ok()) {
    result.reason = st.sequence.reason;
    return false;
  }
  const Isometry3d graph_answer = result.extrinsic;
  result.extrinsic = st.sequence.extrinsic;
  result.time_offset_s = st.sequence.time_offset_s;
  if (st.sequence.has_covariance) {
    // The frame jackknife sees errors that differ between frames; an error every frame shares (a
    // trajectory bias, a modelling error of the whole scene) is invisible to it. The step's
    // move from the graph's (or synchronisation's) C, a second model of the same data, is one
    // sample of that disagreement, and a rerun from refine's own start another: each added as
    // a rank-one term (hots.hpp). When the step adopted a new clock offset, the graph's C was
    // solved at the old one and the move is mostly the offset's change times the speed (60 s
    // 64-32 drive, target 50 ms late: the synchronisation's 27.7 ms left its C 14 cm along the
    // drive from the step's, which found 49.8 ms and lies 1.9 mm from the truth). Nor does the
    // graph give a clean sample at the new offset: its cross links were registered at the old
    // one, and re-solved there (or the synchronisation's mean taken there, or the change taken
    // out by dC/ddt) it still lies 1.0-1.7 cm from the step, which would make sigma 5-9x the
    // error (docs/experiments/graph_move_after_offset.md). The rerun, solved at the step's
    // offset, is then the only sample besides the step's own term for the offset's error
    // (sequence_offset.hpp, offset_error_term).
    const Vec6d moved = st.sequence.time_offset_refined
                            ? Vec6d::Zero()
                            : ulc::se3_log(Isometry3d(graph_answer * result.extrinsic.inverse()));
    result.covariance_6x6 = st.sequence.covariance_6x6 + moved * moved.transpose();
    const Vec6d rerun = rerun_from_start(s, step, result.covariance_6x6, result);
    result.covariance_6x6 += rerun * rerun.transpose();
  }
  st.sequence_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return true;
}

/// The refined poses in the input map frames (b's through T_mapb_mapa).
template <typename S>
void output_poses(const RefineState<S>& s, RefineResult& result) {
  result.poses_a = graph_poses(s, s.a);
  const Isometry3d mapb_mapa = s.mapa_mapb.inverse();
  result.poses_b = graph_poses(s, s.b);
  for (Isometry3d& T : result.poses_b) T = mapb_mapa * T;
}

}  // namespace hots_detail
}  // namespace hots
