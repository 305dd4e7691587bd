// The steps of hots::refine (hots.hpp, whose header comment holds the conventions), each a
// function on the state the call builds: inputs checked, frames prepared, hierarchies, cross
// links, the pose graph and its passes, the whole-sequence step, the poses out.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

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
#include "ulc/core/batched_for.hpp"
#include "ulc/core/deskew.hpp"
#include "ulc/core/mahalanobis.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace hots {

/// What refine builds for one LiDAR from its own frames, timestamps and odometry alone: the frames
/// deskewed and thinned, their sweeps, the hierarchy and its bridges, and the poses the hierarchy
/// gave. Nothing after build_hierarchies changes it, so base LiDAR a's can serve another refine
/// call with the same frames, odometry poses and options (refine's prepared_a).
template <typename S>
struct PreparedLidar {
  std::vector<Isometry3d> built_from;  ///< the odometry poses it was built from
  std::vector<Isometry3d> world;       ///< the odometry's, then the hierarchy's (map a)
  std::vector<std::vector<ulc::Vec3<S>>> frames;
  std::vector<SweepParts<S>> sweeps;  ///< when hierarchy.sweep_parts > 1 (views into frames)
  HierarchyResult<S> hierarchy;
  BoundaryBridges bridges;
};

/// `prepared` was built from exactly these odometry poses (bit for bit).
template <typename S>
bool built_from(const PreparedLidar<S>& prepared, const std::vector<Isometry3d>& poses) {
  if (prepared.built_from.size() != poses.size()) return false;
  for (std::size_t i = 0; i < poses.size(); ++i)
    if (!(prepared.built_from[i].matrix().array() == poses[i].matrix().array()).all()) return false;
  return true;
}

namespace hots_detail {

/// The trust rule on the cross links (see the conventions): enough kept links agree, too few
/// do, or none was kept (too little overlap to judge: HOTS has no evidence for the extrinsic
/// and refuses it too). No attempt: nothing to judge.
inline LinkVerdict judge_links(const RefineStatistics& st, const RefineOptions& options) {
  if (!(options.min_cross_link_ratio > 0.0) || st.cross_links_attempted == 0)
    return LinkVerdict::not_judged;
  if (st.cross_links == 0) return LinkVerdict::too_little_overlap;
  const double needed =
      std::max(static_cast<double>(options.min_cross_links),
               options.min_cross_link_ratio * static_cast<double>(st.cross_links_attempted));
  return static_cast<double>(st.cross_links_agreeing) >= needed ? LinkVerdict::kept_links_agree
                                                                : LinkVerdict::kept_links_refute;
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

/// Seconds since `start`, and `start` moved to now: consecutive phases of one run.
inline double lap(std::chrono::steady_clock::time_point& start) {
  const auto now = std::chrono::steady_clock::now();
  const double s = std::chrono::duration<double>(now - start).count();
  start = now;
  return s;
}

/// Orders a frame's thinned points by part of its sweep (stably: `parts` equal parts of the
/// sweep's duration by each point's time, `times` seconds into the sweep) and returns the parts
/// as views into them, each with its points' mean fraction of the sweep. Without times the frame
/// is one part at fraction 0. The views are the parts without a second copy of the frame.
template <typename S>
SweepParts<S> order_by_part(std::vector<ulc::Vec3<S>>& points, const std::vector<double>* times,
                            const std::pair<Isometry3d, double>& motion, int parts) {
  const std::size_t n = times ? static_cast<std::size_t>(std::max(parts, 1)) : 1;
  std::vector<std::size_t> part(points.size(), 0), count(n, 0);
  std::vector<double> fraction_sum(n, 0.0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double f = times ? (*times)[i] / motion.second : 0.0;
    const int j = std::clamp(static_cast<int>(std::floor(f * static_cast<double>(n))), 0,
                             static_cast<int>(n) - 1);
    part[i] = static_cast<std::size_t>(j);
    ++count[part[i]];
    fraction_sum[part[i]] += f;
  }
  std::vector<std::size_t> start(n, 0);
  for (std::size_t j = 1; j < n; ++j) start[j] = start[j - 1] + count[j - 1];
  std::vector<ulc::Vec3<S>> ordered(points.size());
  std::vector<std::size_t> next = start;
  for (std::size_t i = 0; i < points.size(); ++i) ordered[next[part[i]]++] = points[i];
  points.swap(ordered);
  SweepParts<S> sp;
  sp.deskew = motion.first;
  for (std::size_t j = 0; j < n; ++j) {
    sp.parts.emplace_back(points.data() + start[j], count[j]);
    sp.fraction.push_back(count[j] ? fraction_sum[j] / static_cast<double>(count[j]) : 0.0);
  }
  return sp;
}

/// Deskewed and downsampled copies of every stride-th frame (the others stay empty);
/// sweep(k) gives frame k's motion over its sweep and the sweep's duration. With `sweeps`, each
/// frame's kept points are also ordered by part of the sweep and `sweeps` holds the parts
/// (order_by_part; a frame without point times is one part at fraction 0): views into the
/// returned frames, valid while those vectors are neither copied from nor reallocated.
/// progress (optional) gets the fraction of frames done, every few frames.
template <typename S, class Frames, class Sweep>
std::vector<std::vector<ulc::Vec3<S>>> prepare_frames(const Frames& frames, const Sweep& sweep,
                                                      double voxel, std::size_t stride = 1,
                                                      std::vector<SweepParts<S>>* sweeps = nullptr,
                                                      int parts = 1,
                                                      const ulc::StepProgress& progress = {}) {
  std::vector<std::vector<ulc::Vec3<S>>> out(frames.size());
  if (sweeps) sweeps->assign(frames.size(), SweepParts<S>{});
  stride = std::max<std::size_t>(stride, 1);
  ulc::parallel_for_in_batches(
      frames.size(), ulc::default_batch_size(),
      [&](std::size_t k) {
        if (k % stride != 0) return;
        const std::pair<Isometry3d, double> motion = sweep(k);
        const auto& frame = frames[k];  // once: a FrameSource reads it on each access
        auto deskewed = ulc::deskew(frame, motion.first, motion.second);
        const bool timed = sweeps && ulc::traits::has_time(frame) && motion.second > 0.0;
        if (timed) {
          deskewed.times.resize(deskewed.points.size());
          for (std::size_t i = 0; i < deskewed.points.size(); ++i)
            deskewed.times[i] = ulc::traits::time(frame, i);
        }
        const auto down = ulc::voxel_downsample(deskewed, voxel);
        const auto& cloud = down.ok() ? down.cloud : deskewed;
        out[k].reserve(cloud.points.size());
        for (const auto& p : cloud.points) out[k].push_back(p.template cast<S>());
        if (!sweeps) return;
        const bool split = timed && cloud.times.size() == out[k].size();
        (*sweeps)[k] = order_by_part(out[k], split ? &cloud.times : nullptr, motion, parts);
      },
      [&](std::size_t done) {
        if (progress) progress(static_cast<double>(done) / static_cast<double>(frames.size()));
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
    double voxel, std::vector<SweepParts<S>>* sweeps = nullptr, int parts = 1,
    const ulc::StepProgress& progress = {}) {
  return prepare_frames<S>(
      frames, [&](std::size_t k) { return own_sweep(times, poses, k); }, voxel, 1, sweeps, parts,
      progress);
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

/// Why refine cannot run on these sequences; nullptr when it can.
template <class SeqA, class SeqB>
const char* input_problem(const SeqA& a, const SeqB& b, const Isometry3d& extrinsic,
                          const RefineOptions& options) {
  if (a.frames.size() != a.times.size() || a.frames.size() != a.poses.size() ||
      b.frames.size() != b.times.size() || b.frames.size() != b.poses.size())
    return "frame, time and pose counts differ";
  if (!usable_times(a.times) || !usable_times(b.times))
    return "need two or more strictly increasing times";
  if (!extrinsic.matrix().allFinite()) return "extrinsic not finite";
  for (const auto* list : {&a.poses, &b.poses})
    for (const Isometry3d& T : *list)
      if (!T.matrix().allFinite()) return "a pose is not finite";
  if (!(options.frame_voxel > 0.0) || options.passes < 1 || !(options.extrinsic_sigma_m > 0.0) ||
      !(options.extrinsic_sigma_rad > 0.0))
    return "bad options";
  return nullptr;
}

/// One LiDAR as refine works on it: its timestamps and odometry, what was prepared from them
/// (held by `prepared`, shared when it was reused), the registered top-layer boundaries and its
/// place in the graph.
template <typename S>
struct RefineLidar {
  RefineLidar(const std::vector<double>& t, const std::vector<Isometry3d>& poses,
              std::shared_ptr<PreparedLidar<S>> p)
      : times(t),
        odometry(poses),
        reused(p != nullptr),
        prepared(p ? std::move(p) : std::make_shared<PreparedLidar<S>>()),
        world(prepared->world),
        frames(prepared->frames),
        sweeps(prepared->sweeps),
        hierarchy(prepared->hierarchy),
        bridges(prepared->bridges) {}

  const std::vector<double>& times;
  const std::vector<Isometry3d>& odometry;  ///< the input poses, in the LiDAR's own map
  const bool reused;                        ///< prepared came built: nothing to prepare or build
  const std::shared_ptr<PreparedLidar<S>> prepared;
  std::vector<Isometry3d>& world;
  std::vector<std::vector<ulc::Vec3<S>>>& frames;
  std::vector<SweepParts<S>>& sweeps;
  HierarchyResult<S>& hierarchy;
  BoundaryBridges& bridges;
  std::vector<std::optional<CrossLink>> boundaries;  ///< top-layer boundaries registered
  std::size_t first_var = 0;                         ///< its first pose in the graph
};

/// Everything one refine call builds, step after step.
template <typename S>
struct RefineState {
  /// prepared_a: a's preparation to reuse (built from seq_a's poses), or null.
  template <class SeqA, class SeqB>
  RefineState(const SeqA& seq_a, const SeqB& seq_b, std::shared_ptr<PreparedLidar<S>> prepared_a)
      : a(seq_a.times, seq_a.poses, std::move(prepared_a)), b(seq_b.times, seq_b.poses, nullptr) {}

  RefineLidar<S> a, b;
  Isometry3d start = Isometry3d::Identity();  ///< the extrinsic refine started from
  Isometry3d mapa_mapb = Isometry3d::Identity();
  std::vector<CrossLink> links;
  PoseGraph graph;
  std::size_t extrinsic_var = 0;
  std::size_t first_tie = 0;  ///< the ties are the graph's last factors
  std::chrono::steady_clock::time_point clock = std::chrono::steady_clock::now();
};

/// T_mapa_mapb = P_a(t_a0) C P_b(t_a0)^-1, b's pose interpolated to a's first instant.
template <typename S>
Isometry3d map_b_in_map_a(const RefineLidar<S>& a, const RefineLidar<S>& b,
                          const Isometry3d& extrinsic, double time_offset_s) {
  const double t0 = a.times.front() - time_offset_s;  // b's clock
  const Isometry3d b_at_t0 = time_sync_detail::pose_at(
      b.times, b.odometry, std::clamp(t0, b.times.front(), b.times.back()));
  return a.odometry.front() * extrinsic * b_at_t0.inverse();
}

/// a's share of work that grows with the frames: its frames over both LiDARs'.
inline double share_of_a(std::size_t frames_a, std::size_t frames_b) {
  const double a = static_cast<double>(frames_a);
  return a / std::max(a + static_cast<double>(frames_b), 1.0);
}

/// Both LiDARs' frames deskewed with their own odometry and thinned (statistics: prepare);
/// progress gets the fraction done, a's frames first.
template <typename S, class SeqA, class SeqB>
void prepare_lidars(const SeqA& seq_a, const SeqB& seq_b, RefineState<S>& s,
                    const RefineOptions& options, RefineStatistics& st,
                    const ulc::StepProgress& progress) {
  const int parts = options.hierarchy.sweep_parts;
  const double share_a = s.a.reused ? 0.0 : share_of_a(s.a.times.size(), s.b.times.size());
  for (const auto& T : s.b.odometry) s.b.world.push_back(s.mapa_mapb * T);
  if (!s.a.reused) {
    s.a.prepared->built_from = s.a.odometry;
    s.a.world = s.a.odometry;
    s.a.frames = prepare_frames<S>(seq_a.frames, s.a.times, s.a.odometry, options.frame_voxel,
                                   parts > 1 ? &s.a.sweeps : nullptr, parts,
                                   ulc::progress_within(progress, 0.0, share_a));
  }
  s.b.frames = prepare_frames<S>(seq_b.frames, s.b.times, s.b.odometry, options.frame_voxel,
                                 parts > 1 ? &s.b.sweeps : nullptr, parts,
                                 ulc::progress_within(progress, share_a, 1.0));
  st.prepare_seconds = lap(s.clock);
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
/// extrinsic (see judge_links). Then each LiDAR's top-layer boundaries registered
/// (boundary_links.hpp) (statistics: cross_links).
/// progress gets the fraction of cross links registered.
template <typename S>
bool link_lidars(RefineState<S>& s, double time_offset_s, const RefineOptions& options,
                 RefineStatistics& st, const ulc::StepProgress& progress) {
  CrossLinkStats link_stats;
  s.links = cross_links(s.a.hierarchy, s.a.frames, s.a.times, s.a.world, s.b.hierarchy, s.b.frames,
                        s.b.times, s.b.world, time_offset_s, options.links, &link_stats, progress);
  st.cross_links = s.links.size();
  st.cross_links_attempted = link_stats.attempted;
  st.cross_links_agreeing = link_stats.agreeing;
  st.cross_links_converged = link_stats.converged;
  st.cross_links_weak = link_stats.weak;
  st.cross_links_weak_agreeing = link_stats.weak_agreeing;
  st.cross_link_inlier_ratio_median = link_stats.inlier_ratio_median;
  st.cross_link_records = std::move(link_stats.records);
  // Decided here, before the graph, the synchronisation and the sequence step: their work
  // would rest on an extrinsic the views refuse (and a caller trying several is spared it).
  st.link_verdict = judge_links(st, options);
  if (!confirms(st.link_verdict)) return false;
  if (options.boundary_registration)
    for (RefineLidar<S>* l : {&s.a, &s.b})
      l->boundaries = boundary_links(l->hierarchy, l->frames, l->world, options.links,
                                     options.boundary_radius_m, &l->bridges.bridged);
  st.links_seconds = lap(s.clock);
  return true;
}

/// Factor kinds of the graph (PoseFactor::kind), for its statistics.
enum FactorKind : int { ba_factor = 0, link_factor = 1, tie_factor = 2, boundary_factor = 3 };

inline void add_relative(PoseGraph& graph, std::size_t from, std::size_t to, const Isometry3d& Z,
                         const Mat6d& information, double huber, FactorKind kind) {
  PoseFactor f;
  f.from = from;
  f.to = to;
  f.measured = Z;
  f.sqrt_information = sqrt_information(information);
  f.huber = huber;
  f.kind = kind;
  graph.add_factor(f);
}

/// A factor across each boundary between two top-layer submaps that no window spans: the
/// bridge's BA factors when it has one (already in), else the registered boundary, else the
/// odometry's step across it (when boundary_sigma_* are set).
template <typename S>
void add_boundaries(PoseGraph& graph, const RefineLidar<S>& l, const RefineOptions& options,
                    RefineStatistics& st) {
  if (l.hierarchy.members.empty()) return;
  const bool odometry_boundaries =
      options.boundary_sigma_m > 0.0 && options.boundary_sigma_rad > 0.0;
  const auto& top = l.hierarchy.members.back();
  for (std::size_t m = 0; m + 1 < top.size(); ++m) {
    if (m < l.bridges.bridged.size() && l.bridges.bridged[m]) {
      ++st.boundary_bridges;
      continue;
    }
    if (m < l.boundaries.size() && l.boundaries[m]) {
      const CrossLink& b = *l.boundaries[m];
      add_relative(graph, l.first_var + b.frame_a, l.first_var + b.frame_b, b.measured,
                   b.information, options.link_huber, boundary_factor);
      ++st.boundary_links;
    } else if (odometry_boundaries) {
      const std::size_t from = top[m].end - 1, to = top[m + 1].begin;
      const Mat6d sqrt_info =
          isotropic_sqrt_information(options.boundary_sigma_m, options.boundary_sigma_rad);
      add_relative(graph, l.first_var + from, l.first_var + to,
                   l.odometry[from].inverse() * l.odometry[to],
                   Mat6d(sqrt_info.transpose() * sqrt_info), 0.0, boundary_factor);
    } else {
      continue;
    }
    ++st.boundary_factors;
  }
}

/// The pose graph: a variable per frame (a's first is the gauge) and one for C; the windows'
/// and bridges' BA factors, the cross links and the boundaries. The ties come later (set_ties).
template <typename S>
void build_graph(RefineState<S>& s, const Isometry3d& extrinsic, const RefineOptions& options,
                 RefineStatistics& st) {
  PoseGraph& graph = s.graph;
  s.b.first_var = s.a.world.size();
  for (std::size_t i = 0; i < s.a.world.size(); ++i) graph.add_variable(s.a.world[i], i == 0);
  for (const Isometry3d& T : s.b.world) graph.add_variable(T);
  s.extrinsic_var = graph.add_variable(extrinsic);
  for (const RefineLidar<S>* l : {&s.a, &s.b}) {
    for (const auto& f : l->hierarchy.factors)
      add_relative(graph, l->first_var + f.from, l->first_var + f.to, f.measured, f.information,
                   0.0, ba_factor);
  }
  for (const RefineLidar<S>* l : {&s.a, &s.b}) {
    for (const auto& f : l->bridges.factors)
      add_relative(graph, l->first_var + f.from, l->first_var + f.to, f.measured, f.information,
                   options.bridge_huber, ba_factor);
  }
  st.ba_factors = s.a.hierarchy.factors.size() + s.b.hierarchy.factors.size() +
                  s.a.bridges.factors.size() + s.b.bridges.factors.size();
  for (const auto& l : s.links)
    add_relative(graph, l.frame_a, s.b.first_var + l.frame_b, l.measured, l.information,
                 options.link_huber, link_factor);
  add_boundaries(graph, s.a, options, st);
  add_boundaries(graph, s.b, options, st);
  s.first_tie = graph.factors.size();
}

/// The extrinsic ties at clock offset `offset`, replacing the previous ones: for every b frame
/// whose instant falls inside a's span, r = log((T_a L)^-1 T_b C^-1), with L a's motion from
/// its nearest frame to that instant on the current poses.
template <typename S>
void set_ties(RefineState<S>& s, double offset, const RefineOptions& options,
              RefineStatistics& st) {
  PoseGraph& graph = s.graph;
  graph.factors.resize(s.first_tie);
  const Mat6d tie_sqrt =
      isotropic_sqrt_information(options.extrinsic_sigma_m, options.extrinsic_sigma_rad);
  const std::vector<double>& ta = s.a.times;
  const std::vector<Isometry3d> pa(
      graph.variables.begin(), graph.variables.begin() + static_cast<std::ptrdiff_t>(ta.size()));
  for (std::size_t j = 0; j < s.b.times.size(); ++j) {
    const double t = s.b.times[j] + offset;  // a's clock
    if (t < ta.front() || t > ta.back()) continue;
    const auto [i, L] = a_at(ta, pa, t);
    PoseFactor f;
    f.from = i;
    f.from_offset = L;
    f.to = s.b.first_var + j;
    f.measured_var = s.extrinsic_var;
    f.sqrt_information = tie_sqrt;
    f.kind = tie_factor;
    graph.add_factor(f);
  }
  st.extrinsic_ties = graph.factors.size() - s.first_tie;
}

/// The graph's poses of one LiDAR.
template <typename S>
std::vector<Isometry3d> graph_poses(const RefineState<S>& s, const RefineLidar<S>& l) {
  const auto first = s.graph.variables.begin() + static_cast<std::ptrdiff_t>(l.first_var);
  return std::vector<Isometry3d>(first, first + static_cast<std::ptrdiff_t>(l.world.size()));
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
