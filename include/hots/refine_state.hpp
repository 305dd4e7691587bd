// What one hots::refine call builds and hands from step to step (refine_steps.hpp): each
// LiDAR's prepared frames, hierarchy and place in the graph, the cross links, the graph.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "hots/boundary_bridges.hpp"
#include "hots/cross_links.hpp"
#include "hots/hierarchy.hpp"
#include "hots/pose_graph.hpp"
#include "hots/time_sync.hpp"
#include "ulc/core/point_traits.hpp"

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

/// Seconds since `start`, and `start` moved to now: consecutive phases of one run.
inline double lap(std::chrono::steady_clock::time_point& start) {
  const auto now = std::chrono::steady_clock::now();
  const double s = std::chrono::duration<double>(now - start).count();
  start = now;
  return s;
}

}  // namespace hots_detail
}  // namespace hots
