// A parked rig's first frames stacked into one cloud per LiDAR, for JEEP.
//
// Why: a rig that stood still (stillness.hpp) has known poses, the identity, and JEEP does not
// know it. Over several frame pairs its pose phase lets the poses slide where one LiDAR's slice
// of the scene pins little (ring-5x16's VLP-16s), and over one frame pair a Livox's rosette
// covers too little of its view (the Mid-40's 10-17 cm misses: docs/experiments/
// parked_recordings.md). Stacked frames keep the single frame's pose-free problem and add
// every frame's points: a rosette fills in, a spinning LiDAR's noise averages out in JEEP's
// voxels.
//
//   - Each LiDAR's first ParkedStackOptions::frames frames (from the call's frame_index), their
//     finite points in one ulc::PointCloud of the frames' scalar, without point times: the rig
//     did not move, so there is no sweep to undo.
//   - Both stacks carry the base's first timestamp: they stand for the same stretch of a
//     standing rig, so JEEP pairs them whatever the clocks' offset.
//   - The free-space check still judges the first frames (one instant's rays).
//   - Views: how many of the stacked frames saw each occupied cell of the stack, on average (a
//     spinning LiDAR's frames repeat one another's cells: about the frame count; a Livox's fill
//     new ones: less). JEEP's covariance of the stack is scaled by the larger of the two
//     LiDARs' views (jeep_step in attempt.hpp): its cell jackknife reads the stack's averaged
//     noise, but re-viewing a cell does not average out what is wrong with it (its sampling,
//     the plane it gives). Unscaled, 13 of 92 parked answers fell outside their 3-sigma
//     ellipsoid, errors of 0.5-8 cm on spinning pairs (bench_covariance --parked
//     --parked-seconds 2, seeds 1-3; docs/experiments/parked_recordings.md).
#pragma once

#include <algorithm>
#include <cstddef>
#include <unordered_set>
#include <vector>

#include "odometry/run_odometry.hpp"
#include "pipeline/stillness_options.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/voxel.hpp"

namespace ulc {

template <class Frames>
using stacked_cloud_t = PointCloud<traits::scalar_t<odometry::detail::frame_cloud_t<Frames>>>;

/// How many of `frames` to stack: ParkedStackOptions::frames, at least one (0 counts as 1: the
/// first frame alone) and no more than the recording holds.
template <class Frames>
std::size_t frames_to_stack(const Frames& frames, const ParkedStackOptions& o) {
  return std::min(std::max<std::size_t>(o.frames, 1), static_cast<std::size_t>(frames.size()));
}

/// The finite points of frames[0 .. count) in one cloud, without times (count <= frames.size()).
template <class Frames>
stacked_cloud_t<Frames> stack_frames(const Frames& frames, std::size_t count) {
  stacked_cloud_t<Frames> stack;
  std::size_t total = 0;
  for (std::size_t f = 0; f < count; ++f) total += traits::size(frames[f]);
  stack.points.reserve(total);
  for (std::size_t f = 0; f < count; ++f) {
    const auto& cloud = frames[f];
    for (std::size_t i = 0; i < traits::size(cloud); ++i) {
      const auto p = traits::point(cloud, i);
      if (p.allFinite()) stack.points.push_back(p);
    }
  }
  return stack;
}

/// The cells (edge `cell`, m) the finite points of one cloud fall in.
template <class Cloud>
std::unordered_set<VoxelKey, VoxelKeyHash> occupied_cells(const Cloud& cloud, double cell) {
  std::unordered_set<VoxelKey, VoxelKeyHash> cells;
  for (std::size_t i = 0; i < traits::size(cloud); ++i)
    if (const auto key = make_voxel_key(traits::point(cloud, i), cell)) cells.insert(*key);
  return cells;
}

/// Frames per occupied cell of frames[0 .. count) stacked, on average (1 for one frame; 0 for
/// no points; count <= frames.size()).
template <class Frames>
double views_per_cell(const Frames& frames, std::size_t count, double cell) {
  std::unordered_set<VoxelKey, VoxelKeyHash> all;
  std::size_t seen = 0;
  for (std::size_t f = 0; f < count; ++f) {
    const auto cells = occupied_cells(frames[f], cell);
    seen += cells.size();
    all.insert(cells.begin(), cells.end());
  }
  return all.empty() ? 0.0 : static_cast<double>(seen) / static_cast<double>(all.size());
}

/// Both LiDARs' stacks as one-frame sequences JEEP reads.
template <class FramesA, class FramesB>
struct ParkedStack {
  std::vector<stacked_cloud_t<FramesA>> a;
  std::vector<stacked_cloud_t<FramesB>> b;
  std::vector<double> times_a, times_b;
  std::size_t frames_a = 0, frames_b = 0;  ///< frames stacked into each
  double views_a = 0.0, views_b = 0.0;     ///< frames per occupied cell of each stack
  /// What JEEP's covariance of the stacks is scaled by (see the header comment).
  double covariance_scale() const { return std::max({1.0, views_a, views_b}); }
};

/// The stacks, their views counted in cells of edge `cell` (m; JEEP's finest source voxel).
template <class FramesA, class FramesB>
ParkedStack<FramesA, FramesB> parked_stack(const FramesA& frames_a,
                                           const std::vector<double>& times_a,
                                           const FramesB& frames_b, const ParkedStackOptions& o,
                                           double cell) {
  ParkedStack<FramesA, FramesB> s;
  s.frames_a = frames_to_stack(frames_a, o);
  s.frames_b = frames_to_stack(frames_b, o);
  s.a.push_back(stack_frames(frames_a, s.frames_a));
  s.b.push_back(stack_frames(frames_b, s.frames_b));
  s.views_a = views_per_cell(frames_a, s.frames_a, cell);
  s.views_b = views_per_cell(frames_b, s.frames_b, cell);
  s.times_a = s.times_b = {times_a.empty() ? 0.0 : times_a.front()};
  return s;
}

}  // namespace ulc
