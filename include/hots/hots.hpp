// HOTS: hierarchical optimisation and time synchronisation, the last stages of the paper
// (Sec. "Pose Refinement by Hierarchical Optimization" and "Time Synchronization"):
//   frames + odometry poses of LiDARs a (base) and b (target) + an extrinsic
//   -> deskewed, downsampled frames -> one hierarchy per LiDAR (hierarchy.hpp)
//   -> cross-LiDAR links (cross_links.hpp) -> one pose graph with the extrinsic as a variable,
//      solved by our sparse LM (pose_graph.hpp, sparse_lm.hpp)
//   -> time synchronisation on the refined poses (time_sync.hpp)
//   -> every target frame against the base's submaps through the base's refined trajectory
//      (sequence_extrinsic.hpp) -> extrinsic, clock offset.
//
// Conventions this header owns:
//   - Inputs: frames (random-access containers of traits clouds, points in the LiDAR frame at
//     each point's own time, per-point times relative to the frame timestamp when the cloud has
//     them), timestamps (own clocks), poses_a = T_mapa_a and poses_b = T_mapb_b at the frame
//     timestamps, each LiDAR in its own map frame (as jeep's odometry gives them), and the
//     extrinsic C = T_base_target. Clock offset: t_a = t_b + time_offset_s (docs/design.md).
//   - The two maps are put in one world (map a) by T_mapa_mapb = P_a(t_a0) C P_b(t_a0)^-1 at
//     a's first frame, b's pose interpolated to that instant (identity-free for jeep's
//     odometry, whose map b is b's frame at a's first instant: T_mapa_mapb = C).
//   - Frames are deskewed with the motion between their pose and the next frame's (constant
//     velocity), then voxel-downsampled (frame_voxel). With hierarchy.sweep_parts > 1 each
//     frame's points are also split by time into that many parts, and the hierarchy's layer 0
//     treats every frame as a sweep between its pose and the next frame's (sweep_ba.hpp).
//   - Pose graph: one variable per frame of a and b (T_world_frame) and one for C; a's first
//     frame is the gauge. Factors: every window's BA (information from its Hessian), every
//     cross link (Huber), each boundary between two top-layer submaps (no window spans it:
//     without a factor each top submap would float on its own, held only by the damping): a
//     bridge BA over the members on both sides (boundary_bridges.hpp, with boundary_bridges),
//     else the two submaps registered to each other (boundary_links.hpp), else the odometry's
//     step across it, and for every b frame an extrinsic tie to the a frame nearest its
//     instant, with a's motion to that instant taken from the current poses:
//     r = log((T_a L)^-1 T_b C^-1) (isotropic information, extrinsic_sigma_*). The ties know the
//     clock offset only through the current estimate, so they are deliberately weak: the
//     offset itself comes from the time synchronisation, and a second pass (passes = 2)
//     rebuilds the ties with it.
//   - Result extrinsic and offset = the whole-sequence step's (sequence_extrinsic.hpp),
//     started from the time synchronisation's mean (eq:mean) and offset (without
//     synchronisation: the graph's C and time_offset_s); with that step disabled, its start.
//     statistics keep the graph's and the synchronisation's answers. covariance_6x6 = the spread of
//     the per-pair extrinsics ([rho; phi], left); without synchronisation, the graph's marginal
//     covariance of C.
//   - refined poses are returned in the input map frames (b's through T_mapa_mapb).
//   - With time synchronisation on, the whole-sequence step checks that the drive pins the
//     clock offset down (sequence_extrinsic.hpp, check_time_offset); when it does not, the
//     status is time_offset_untrusted and reason says why: the extrinsic absorbs v * (the
//     offset's error), so the result cannot be trusted. A caller who knows the offset turns
//     the synchronisation off and passes it as time_offset_s.
//   - The extrinsic must be confirmed by the LiDARs' own views: the cross links register b's
//     submaps to a's from the prediction of the starting extrinsic, and a kept link agrees
//     with it when the registration moved less than 1 deg and 1 m from that start
//     (cross_links.hpp). When fewer than max(min_cross_links, min_cross_link_ratio *
//     attempted) links agree, the status is extrinsic_unconfirmed, decided right after the
//     links, before the pose graph (the result's extrinsic and poses are then the inputs). The
//     graph cannot repair such a start: its ties hold C where it began and a planar drive leaves
//     the two trajectories' consistency degenerate. Measured (bench_trust and the seven-LiDAR rig,
//     docs/experiments/cross_link_agreement.md): wrong extrinsics JEEP accepted
//     had 0-1 agreeing links of 90 (64-tele, horizon-tele) and 0 of 538 (the rig's Tele, whose 27
//     kept links all moved 1.6-14.8 deg); right ones on the Tele pairs at least 8 of 90 and 35 of
//     538.
//   - Nothing here throws or prints; results are the same for any number of threads.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hots/boundary_bridges.hpp"
#include "hots/boundary_links.hpp"
#include "hots/cross_links.hpp"
#include "hots/hierarchy.hpp"
#include "hots/options.hpp"
#include "hots/pose_graph.hpp"
#include "hots/refine_statistics.hpp"
#include "hots/sequence_extrinsic.hpp"
#include "hots/sparse_lm.hpp"
#include "hots/time_sync.hpp"
#include "ulc/core/deskew.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace hots {

namespace hots_detail {

/// The trust rule on the cross links (see the conventions); no attempt: nothing to judge.
inline bool links_confirm(const RefineStatistics& st, const RefineOptions& options) {
  if (!(options.min_cross_link_ratio > 0.0) || st.cross_links_attempted == 0) return true;
  const double needed =
      std::max(static_cast<double>(options.min_cross_links),
               options.min_cross_link_ratio * static_cast<double>(st.cross_links_attempted));
  return static_cast<double>(st.cross_links_agreeing) >= needed;
}

/// Seconds since `start`, and `start` moved to now: consecutive phases of one run.
inline double lap(std::chrono::steady_clock::time_point& start) {
  const auto now = std::chrono::steady_clock::now();
  const double s = std::chrono::duration<double>(now - start).count();
  start = now;
  return s;
}

/// Deskewed and downsampled copies of every stride-th frame (the others stay empty);
/// sweep(k) gives frame k's motion over its sweep and the sweep's duration. With `sweeps`, each
/// frame's kept points are also split by time into `parts` equal parts of the sweep
/// (hierarchy.hpp, SweepParts; a frame without point times is one part at fraction 0).
template <typename S, class Frames, class Sweep>
std::vector<std::vector<ulc::Vec3<S>>> prepare_frames(const Frames& frames, const Sweep& sweep,
                                                      double voxel, std::size_t stride = 1,
                                                      std::vector<SweepParts<S>>* sweeps = nullptr,
                                                      int parts = 1) {
  std::vector<std::vector<ulc::Vec3<S>>> out(frames.size());
  if (sweeps) sweeps->assign(frames.size(), SweepParts<S>{});
  stride = std::max<std::size_t>(stride, 1);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, frames.size(), 1),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
          if (k % stride != 0) continue;
          const std::pair<Isometry3d, double> motion = sweep(k);
          auto deskewed = ulc::deskew(frames[k], motion.first, motion.second);
          const bool timed = sweeps && ulc::traits::has_time(frames[k]) && motion.second > 0.0;
          if (timed) {
            deskewed.times.resize(deskewed.points.size());
            for (std::size_t i = 0; i < deskewed.points.size(); ++i)
              deskewed.times[i] = ulc::traits::time(frames[k], i);
          }
          const auto down = ulc::voxel_downsample(deskewed, voxel);
          const auto& cloud = down.ok() ? down.cloud : deskewed;
          out[k].reserve(cloud.points.size());
          for (const auto& p : cloud.points) out[k].push_back(p.template cast<S>());
          if (!sweeps) continue;
          SweepParts<S>& sp = (*sweeps)[k];
          sp.deskew = motion.first;
          const bool split = timed && cloud.times.size() == out[k].size();
          const int n = split ? std::max(parts, 1) : 1;
          sp.parts.assign(static_cast<std::size_t>(n), {});
          std::vector<double> time_sum(static_cast<std::size_t>(n), 0.0);
          for (std::size_t i = 0; i < out[k].size(); ++i) {
            const double f = split ? cloud.times[i] / motion.second : 0.0;
            const auto j =
                static_cast<std::size_t>(std::clamp(static_cast<int>(std::floor(f * n)), 0, n - 1));
            sp.parts[j].push_back(out[k][i]);
            time_sum[j] += f;
          }
          for (std::size_t j = 0; j < sp.parts.size(); ++j)
            sp.fraction.push_back(
                sp.parts[j].empty() ? 0.0 : time_sum[j] / static_cast<double>(sp.parts[j].size()));
        }
      });
  return out;
}

/// Constant velocity from a LiDAR's own poses: the motion to the next frame.
inline std::pair<Isometry3d, double> own_sweep(const std::vector<double>& times,
                                               const std::vector<Isometry3d>& poses,
                                               std::size_t k) {
  const std::size_t j = k + 1 < times.size() ? k : k - 1;
  return {poses[j].inverse() * poses[j + 1], times[j + 1] - times[j]};
}

/// Every frame deskewed with its LiDAR's own poses (own_sweep).
template <typename S, class Frames>
std::vector<std::vector<ulc::Vec3<S>>> prepare_frames(
    const Frames& frames, const std::vector<double>& times, const std::vector<Isometry3d>& poses,
    double voxel, std::vector<SweepParts<S>>* sweeps = nullptr, int parts = 1) {
  return prepare_frames<S>(
      frames, [&](std::size_t k) { return own_sweep(times, poses, k); }, voxel, 1, sweeps, parts);
}

/// b's sweep from the base's trajectory T_world_a through C at b's instant t_b + dt:
/// C^-1 T_a(t)^-1 T_a(t + D) C with D b's frame period.
inline std::pair<Isometry3d, double> base_sweep(const std::vector<double>& times_b,
                                                const std::vector<double>& times_a,
                                                const std::vector<Isometry3d>& world_a,
                                                const Isometry3d& C, double dt, std::size_t k) {
  const std::size_t j = k + 1 < times_b.size() ? k : k - 1;
  const double duration = times_b[j + 1] - times_b[j];
  const double t = times_b[k] + dt;
  const Isometry3d motion = time_sync_detail::pose_at(times_a, world_a, t).inverse() *
                            time_sync_detail::pose_at(times_a, world_a, t + duration);
  return {C.inverse() * motion * C, duration};
}

/// The a frame nearest to t (a's clock) and a's motion from it to t (interpolated or
/// extrapolated with the neighbouring frame).
inline std::pair<std::size_t, Isometry3d> a_at(const std::vector<double>& times,
                                               const std::vector<Isometry3d>& poses, double t) {
  auto it = std::lower_bound(times.begin(), times.end(), t);
  std::size_t k = static_cast<std::size_t>(it - times.begin());
  if (k == times.size() || (k > 0 && t - times[k - 1] <= times[k] - t)) --k;
  const std::size_t j = t >= times[k] ? std::min(k, times.size() - 2) : (k > 0 ? k - 1 : 0);
  const double span = times[j + 1] - times[j];
  const double alpha = span > 0.0 ? (t - times[j]) / span : 0.0;
  const Isometry3d at_t = ulc::interpolate(poses[j], poses[j + 1], alpha);
  return {k, poses[k].inverse() * at_t};
}

inline bool usable_times(const std::vector<double>& t) {
  if (t.size() < 2) return false;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i])) return false;
    if (i > 0 && !(t[i] > t[i - 1])) return false;
  }
  return true;
}

}  // namespace hots_detail

/// See the header comment. S is the scalar of the prepared point clouds (float is plenty).
template <typename S = float, class FramesA, class FramesB>
RefineResult refine(const FramesA& frames_a, const std::vector<double>& times_a,
                    const std::vector<Isometry3d>& poses_a, const FramesB& frames_b,
                    const std::vector<double>& times_b, const std::vector<Isometry3d>& poses_b,
                    const Isometry3d& extrinsic, const RefineOptions& options = {}) {
  namespace d = hots_detail;
  RefineResult result;
  result.extrinsic = extrinsic;
  result.poses_a = poses_a;
  result.poses_b = poses_b;
  result.time_offset_s = options.time_offset_s;
  auto fail = [&](RefineStatus s, const char* why) {
    result.status = s;
    result.reason = why;
    return result;
  };
  if (frames_a.size() != times_a.size() || frames_a.size() != poses_a.size() ||
      frames_b.size() != times_b.size() || frames_b.size() != poses_b.size())
    return fail(RefineStatus::invalid_input, "frame, time and pose counts differ");
  if (!d::usable_times(times_a) || !d::usable_times(times_b))
    return fail(RefineStatus::invalid_input, "need two or more strictly increasing times");
  if (!extrinsic.matrix().allFinite())
    return fail(RefineStatus::invalid_input, "extrinsic not finite");
  for (const auto* list : {&poses_a, &poses_b})
    for (const Isometry3d& T : *list)
      if (!T.matrix().allFinite()) return fail(RefineStatus::invalid_input, "a pose is not finite");
  if (!(options.frame_voxel > 0.0) || options.passes < 1 || !(options.extrinsic_sigma_m > 0.0) ||
      !(options.extrinsic_sigma_rad > 0.0))
    return fail(RefineStatus::invalid_input, "bad options");

  // One world: map a.
  const double t0 = times_a.front() - options.time_offset_s;  // b's clock
  const Isometry3d b_at_t0 =
      time_sync_detail::pose_at(times_b, poses_b, std::clamp(t0, times_b.front(), times_b.back()));
  const Isometry3d mapa_mapb = poses_a.front() * extrinsic * b_at_t0.inverse();
  std::vector<Isometry3d> world_a = poses_a, world_b;
  for (const auto& T : poses_b) world_b.push_back(mapa_mapb * T);

  RefineStatistics& st = result.statistics;
  auto clock = std::chrono::steady_clock::now();
  const int parts = options.hierarchy.sweep_parts;
  std::vector<SweepParts<S>> sweeps_a, sweeps_b;
  const auto fa = d::prepare_frames<S>(frames_a, times_a, poses_a, options.frame_voxel,
                                       parts > 1 ? &sweeps_a : nullptr, parts);
  const auto fb = d::prepare_frames<S>(frames_b, times_b, poses_b, options.frame_voxel,
                                       parts > 1 ? &sweeps_b : nullptr, parts);
  st.prepare_seconds = d::lap(clock);

  const auto ha = build_hierarchy(fa, world_a, options.hierarchy, parts > 1 ? &sweeps_a : nullptr);
  const auto hb = build_hierarchy(fb, world_b, options.hierarchy, parts > 1 ? &sweeps_b : nullptr);
  const auto bridges_a =
      options.boundary_bridges ? boundary_bridges(ha, fa, options.hierarchy) : BoundaryBridges{};
  const auto bridges_b =
      options.boundary_bridges ? boundary_bridges(hb, fb, options.hierarchy) : BoundaryBridges{};
  st.hierarchy_seconds = d::lap(clock);
  st.windows = ha.windows + hb.windows + bridges_a.windows + bridges_b.windows;
  st.failed_windows = ha.failed_windows + hb.failed_windows;
  st.planes = ha.planes + hb.planes + bridges_a.planes + bridges_b.planes;
  world_a = ha.poses;
  world_b = hb.poses;

  CrossLinkStats link_stats;
  const auto links = cross_links(ha, fa, times_a, world_a, hb, fb, times_b, world_b,
                                 options.time_offset_s, options.links, &link_stats);
  st.cross_links = links.size();
  st.cross_links_attempted = link_stats.attempted;
  st.cross_links_agreeing = link_stats.agreeing;
  // Decided here, before the graph, the synchronisation and the sequence step: their work
  // would rest on an extrinsic the views refuse (and a caller trying several is spared it).
  if (!hots_detail::links_confirm(st, options))
    return fail(RefineStatus::extrinsic_unconfirmed,
                "too few of the cross links (b's submaps registered to a's through the "
                "extrinsic) agree with it: the two LiDARs' views do not confirm the extrinsic "
                "(statistics: cross_links_agreeing of cross_links_attempted)");
  using BoundaryLinks = std::vector<std::optional<CrossLink>>;
  const BoundaryLinks boundary_a =
      options.boundary_registration ? boundary_links(ha, fa, world_a, options.links,
                                                     options.boundary_radius_m, &bridges_a.bridged)
                                    : BoundaryLinks{};
  const BoundaryLinks boundary_b =
      options.boundary_registration ? boundary_links(hb, fb, world_b, options.links,
                                                     options.boundary_radius_m, &bridges_b.bridged)
                                    : BoundaryLinks{};
  st.links_seconds = d::lap(clock);

  const std::size_t na = frames_a.size(), nb = frames_b.size();
  PoseGraph graph;
  for (std::size_t i = 0; i < na; ++i) graph.add_variable(world_a[i], i == 0);
  for (std::size_t j = 0; j < nb; ++j) graph.add_variable(world_b[j]);
  const std::size_t c_var = graph.add_variable(extrinsic);
  auto add_relative = [&](std::size_t from, std::size_t to, const Isometry3d& Z, const Mat6d& info,
                          double huber, int kind) {
    PoseFactor f;
    f.from = from;
    f.to = to;
    f.measured = Z;
    f.sqrt_information = sqrt_information(info);
    f.huber = huber;
    f.kind = kind;
    graph.add_factor(f);
  };
  for (const auto& f : ha.factors) add_relative(f.from, f.to, f.measured, f.information, 0.0, 0);
  for (const auto& f : hb.factors)
    add_relative(na + f.from, na + f.to, f.measured, f.information, 0.0, 0);
  for (const auto& f : bridges_a.factors)
    add_relative(f.from, f.to, f.measured, f.information, options.bridge_huber, 0);
  for (const auto& f : bridges_b.factors)
    add_relative(na + f.from, na + f.to, f.measured, f.information, options.bridge_huber, 0);
  st.ba_factors =
      ha.factors.size() + hb.factors.size() + bridges_a.factors.size() + bridges_b.factors.size();
  for (const auto& l : links)
    add_relative(l.frame_a, na + l.frame_b, l.measured, l.information, options.link_huber, 1);
  const bool odometry_boundaries =
      options.boundary_sigma_m > 0.0 && options.boundary_sigma_rad > 0.0;
  auto add_boundaries = [&](const auto& hierarchy, const BoundaryBridges& bridges,
                            const BoundaryLinks& registered,
                            const std::vector<Isometry3d>& odometry, std::size_t first_var) {
    if (hierarchy.members.empty()) return;
    const auto& top = hierarchy.members.back();
    for (std::size_t m = 0; m + 1 < top.size(); ++m) {
      if (m < bridges.bridged.size() && bridges.bridged[m]) {
        ++st.boundary_bridges;  // its factors are among the BA's
        continue;
      }
      if (m < registered.size() && registered[m]) {
        const CrossLink& l = *registered[m];
        add_relative(first_var + l.frame_a, first_var + l.frame_b, l.measured, l.information,
                     options.link_huber, 3);
        ++st.boundary_links;
      } else if (odometry_boundaries) {
        const std::size_t from = top[m].end - 1, to = top[m + 1].begin;
        const Mat6d sqrt_info =
            isotropic_sqrt_information(options.boundary_sigma_m, options.boundary_sigma_rad);
        add_relative(first_var + from, first_var + to, odometry[from].inverse() * odometry[to],
                     Mat6d(sqrt_info.transpose() * sqrt_info), 0.0, 3);
      } else {
        continue;
      }
      ++st.boundary_factors;
    }
  };
  add_boundaries(ha, bridges_a, boundary_a, poses_a, 0);
  add_boundaries(hb, bridges_b, boundary_b, poses_b, na);
  const std::size_t first_tie = graph.factors.size();
  const Mat6d tie_sqrt =
      isotropic_sqrt_information(options.extrinsic_sigma_m, options.extrinsic_sigma_rad);
  auto set_ties = [&](double offset) {
    graph.factors.resize(first_tie);
    std::vector<double> ta = times_a;
    std::vector<Isometry3d> pa(graph.variables.begin(),
                               graph.variables.begin() + static_cast<std::ptrdiff_t>(na));
    for (std::size_t j = 0; j < nb; ++j) {
      const double t = times_b[j] + offset;  // a's clock
      if (t < times_a.front() || t > times_a.back()) continue;
      const auto [i, L] = d::a_at(ta, pa, t);
      PoseFactor f;
      f.from = i;
      f.from_offset = L;
      f.to = na + j;
      f.measured_var = c_var;
      f.sqrt_information = tie_sqrt;
      f.kind = 2;
      graph.add_factor(f);
    }
    st.extrinsic_ties = graph.factors.size() - first_tie;
  };

  double offset = options.time_offset_s;
  for (int pass = 0; pass < options.passes; ++pass) {
    set_ties(offset);
    d::lap(clock);
    const SparseLmResult lm = solve_pose_graph(graph, options.solver);
    st.graph_seconds += d::lap(clock);
    if (pass == 0) st.graph_initial_cost = lm.initial_cost;
    st.graph_cost = lm.cost;
    st.graph_iterations += lm.iterations;
    if (!(lm.ok() || lm.status == SparseLmStatus::not_converged))
      return fail(RefineStatus::graph_failed, lm.reason);
    st.graph_extrinsic = graph.variables[c_var];
    result.extrinsic = graph.variables[c_var];
    if (!options.synchronise_time) {
      result.covariance_6x6 = marginal_covariance(graph, c_var, options.solver.grain);
      break;
    }
    std::vector<Isometry3d> wa(graph.variables.begin(),
                               graph.variables.begin() + static_cast<std::ptrdiff_t>(na));
    std::vector<Isometry3d> wb(graph.variables.begin() + static_cast<std::ptrdiff_t>(na),
                               graph.variables.begin() + static_cast<std::ptrdiff_t>(na + nb));
    TimeSyncOptions ts = options.time_sync;
    ts.centre_s = options.time_offset_s;
    const TimeSyncResult sync = time_sync(times_a, wa, times_b, wb, ts);
    st.sync_seconds += d::lap(clock);
    if (!sync.ok()) return fail(RefineStatus::time_sync_failed, sync.reason);
    offset = sync.time_offset_s;
    result.time_offset_s = offset;
    result.extrinsic = sync.extrinsic;
    result.covariance_6x6 = sync.covariance;
    result.spread_curve = sync.curve;
    st.time_sync_spread = sync.spread;
    st.time_sync_pairs = sync.pairs;
    st.sync_extrinsic = sync.extrinsic;
    st.sync_time_offset_s = sync.time_offset_s;
    st.sync_significant = sync.significant;
    graph.variables[c_var] = sync.extrinsic;
  }

  if (options.sequence.enabled) {
    const std::vector<Isometry3d> wa(graph.variables.begin(),
                                     graph.variables.begin() + static_cast<std::ptrdiff_t>(na));
    // The joint dt is refined only where the synchronisation found an offset at all: its
    // significance test is what keeps a synchronised rig at exactly zero.
    SequenceExtrinsicOptions so = options.sequence;
    so.estimate_time_offset = so.estimate_time_offset && st.sync_significant;
    // Without synchronisation the offset is the caller's (known clocks): nothing to check.
    so.check_time_offset = so.check_time_offset && options.synchronise_time;
    const auto t0 = std::chrono::steady_clock::now();
    // b's frames deskewed afresh through the base's refined motion (deskew_from_base).
    std::vector<std::vector<ulc::Vec3<S>>> fb_base;
    if (so.deskew_from_base)
      fb_base = d::prepare_frames<S>(
          frames_b,
          [&](std::size_t k) {
            return d::base_sweep(times_b, times_a, wa, result.extrinsic, result.time_offset_s, k);
          },
          options.frame_voxel, so.frame_stride);
    st.sequence = sequence_extrinsic(ha, fa, times_a, wa, so.deskew_from_base ? fb_base : fb,
                                     times_b, result.extrinsic, result.time_offset_s, so);
    st.sequence_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!st.sequence.ok()) return fail(RefineStatus::sequence_failed, st.sequence.reason);
    result.extrinsic = st.sequence.extrinsic;
    result.time_offset_s = st.sequence.time_offset_s;
  }

  const Isometry3d mapb_mapa = mapa_mapb.inverse();
  for (std::size_t i = 0; i < na; ++i) result.poses_a[i] = graph.variables[i];
  for (std::size_t j = 0; j < nb; ++j) result.poses_b[j] = mapb_mapa * graph.variables[na + j];
  if (!st.sequence.time_offset_trusted)
    return fail(RefineStatus::time_offset_untrusted, st.sequence.time_offset_doubt);
  return result;
}

}  // namespace hots
