// Planes of a window of frames: voxelise the frames' points placed by their poses, split each
// voxel octree-style until its points are planar, and keep, per plane, one point cluster per
// frame in that frame's body coordinates (the inputs of point_cluster.hpp's plane cost).
//
// Conventions this header owns:
//   - Frames are any traits clouds (ulc::traits), points in their body frame; poses are
//     T_window_frame. Non-finite points are skipped.
//   - Root voxels are those of ulc/core/voxel.hpp with edge `voxel_size`; a cell is split into
//     its 8 octants (about the cell's centre) up to `max_depth` times.
//   - A cell is a plane when it has at least `min_points` points from at least `min_frames`
//     frames, lambda_0 / lambda_1 <= max_eigen_ratio (eigenvalues of the cell's covariance,
//     ascending) and every point within max_distance of the fitted plane: a corner cell where
//     a strip of a second surface hides in an otherwise thin cloud fails the second test. Cells
//     that are not, and cannot be split further, are dropped. A cell seen by fewer than min_frames
//     frames is dropped unsplit (its cost does not depend on the relative poses).
//   - Output order: root voxels in order of their first point (frames in order, points in
//     order), octants in a fixed order within: the same planes for any number of threads.
//   - Nothing here throws or prints.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hots/options.hpp"
#include "hots/point_cluster.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/voxel.hpp"

namespace hots {

/// A plane of the window: its anchor (the mean of its points at the extraction poses) and the
/// cluster of each frame that sees it (frame = index into the window).
struct Plane {
  Vec3d anchor = Vec3d::Zero();
  std::vector<FrameCluster> frames;
  std::size_t points = 0;
};

namespace plane_detail {

struct WindowPoint {
  Vec3d world;  ///< placed in the window frame
  Vec3d body;
  std::uint32_t frame;
};

inline void extract_cell(const std::vector<WindowPoint>& points, std::vector<std::uint32_t>& cell,
                         const Vec3d& centre, double half, int depth, std::size_t n_frames,
                         const PlaneExtractionOptions& o, std::vector<Plane>& out) {
  if (cell.size() < o.min_points) return;
  std::vector<std::uint32_t> per_frame(n_frames, 0);
  std::size_t frames_seen = 0;
  PointCluster placed(points[cell[0]].world);
  for (const std::uint32_t i : cell) {
    if (per_frame[points[i].frame]++ == 0) ++frames_seen;
    placed.add(points[i].world);
  }
  if (frames_seen < o.min_frames) return;
  const Mat3d M = placed.scatter();
  // Closed form, as for the normals (ulc/core/normals.hpp): the planarity test and the
  // normal need l0 apart from l1, where it is accurate.
  Eigen::SelfAdjointEigenSolver<Mat3d> solver;
  solver.computeDirect(M);
  const Vec3d lambda = solver.eigenvalues();
  bool planar = lambda(1) > 0.0 && lambda(0) <= o.max_eigen_ratio * lambda(1);
  if (planar) {
    const Vec3d normal = solver.eigenvectors().col(0);
    const Vec3d mean = placed.mean();
    for (const std::uint32_t i : cell) {
      if (std::abs(normal.dot(points[i].world - mean)) > o.max_distance) {
        planar = false;
        break;
      }
    }
  }
  if (planar) {
    Plane plane;
    plane.anchor = placed.mean();
    plane.points = cell.size();
    std::vector<int> slot(n_frames, -1);
    for (const std::uint32_t i : cell) {
      const std::uint32_t f = points[i].frame;
      if (slot[f] < 0) {
        slot[f] = static_cast<int>(plane.frames.size());
        plane.frames.push_back(FrameCluster{f, PointCluster(points[i].body)});
      }
    }
    // Frames in ascending order, so a plane lists its frames the same way every time.
    std::sort(plane.frames.begin(), plane.frames.end(),
              [](const FrameCluster& a, const FrameCluster& b) { return a.frame < b.frame; });
    for (std::size_t k = 0; k < plane.frames.size(); ++k)
      slot[plane.frames[k].frame] = static_cast<int>(k);
    for (const std::uint32_t i : cell)
      plane.frames[static_cast<std::size_t>(slot[points[i].frame])].cluster.add(points[i].body);
    out.push_back(std::move(plane));
    return;
  }
  if (depth >= o.max_depth) return;
  std::array<std::vector<std::uint32_t>, 8> octants;
  for (const std::uint32_t i : cell) {
    const Vec3d& x = points[i].world;
    const int k = (x.x() >= centre.x() ? 1 : 0) | (x.y() >= centre.y() ? 2 : 0) |
                  (x.z() >= centre.z() ? 4 : 0);
    octants[static_cast<std::size_t>(k)].push_back(i);
  }
  std::vector<std::uint32_t>().swap(cell);  // children own the points now
  const double q = half / 2;
  for (int k = 0; k < 8; ++k) {
    const Vec3d child(centre.x() + ((k & 1) ? q : -q), centre.y() + ((k & 2) ? q : -q),
                      centre.z() + ((k & 4) ? q : -q));
    extract_cell(points, octants[static_cast<std::size_t>(k)], child, q, depth + 1, n_frames, o,
                 out);
  }
}

constexpr std::size_t kVoxelGrain = 16;

/// The window's usable points (finite, with a voxel) in frame order, each with its root voxel.
struct WindowPoints {
  std::vector<WindowPoint> points;
  std::vector<ulc::VoxelKey> keys;  ///< keys[i]: the root voxel of points[i]
};

template <class Cloud>
WindowPoints place_points(const std::vector<const Cloud*>& frames,
                          const std::vector<Isometry3d>& poses, const PlaneExtractionOptions& o) {
  std::size_t total = 0;
  for (const Cloud* frame : frames)
    if (frame) total += ulc::traits::size(*frame);
  WindowPoints window;
  window.points.reserve(total);
  window.keys.reserve(total);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (!frames[f]) continue;
    const Cloud& cloud = *frames[f];
    const std::size_t n = ulc::traits::size(cloud);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3d body = ulc::traits::point(cloud, i).template cast<double>();
      if (!body.allFinite()) continue;
      const Vec3d world = poses[f] * body;
      const auto key = ulc::make_voxel_key(world, o.voxel_size);
      if (!key) continue;
      window.points.push_back({world, body, static_cast<std::uint32_t>(f)});
      window.keys.push_back(*key);
    }
  }
  return window;
}

/// Root voxels in order of their first point; voxel v holds the points
/// members[start[v] .. start[v + 1]), ascending (a counting sort: no list per voxel).
struct RootVoxels {
  std::vector<ulc::VoxelKey> keys;
  std::vector<std::uint32_t> start;
  std::vector<std::uint32_t> members;
};

inline RootVoxels group_by_voxel(const WindowPoints& window) {
  const std::size_t n = window.points.size();
  ulc::VoxelMap<std::uint32_t> counts;  // key -> points in it
  counts.reserve(n / 4 + 16);
  std::vector<std::uint32_t> voxel_of(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t position = counts.try_emplace(window.keys[i], 0u).first;
    ++counts.at_position(position).value;
    voxel_of[i] = static_cast<std::uint32_t>(position);
  }
  RootVoxels roots;
  roots.keys.reserve(counts.size());
  roots.start.assign(counts.size() + 1, 0);
  for (std::size_t v = 0; v < counts.size(); ++v) {
    roots.keys.push_back(counts.at_position(v).key);
    roots.start[v + 1] = roots.start[v] + counts.at_position(v).value;
  }
  std::vector<std::uint32_t> next(roots.start.begin(), roots.start.end() - 1);
  roots.members.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    roots.members[next[voxel_of[i]]++] = static_cast<std::uint32_t>(i);
  return roots;
}

}  // namespace plane_detail

inline bool valid_plane_extraction_options(const PlaneExtractionOptions& o) {
  return o.voxel_size > 0.0 && std::isfinite(o.voxel_size) && o.max_depth >= 0 &&
         o.max_depth <= 16 && o.min_points >= 3 && o.min_frames >= 1 && o.max_eigen_ratio > 0.0 &&
         o.max_distance > 0.0;
}

/// The planes of the frames placed by `poses` (T_window_frame), see the header comment.
template <class Cloud>
std::vector<Plane> extract_planes(const std::vector<const Cloud*>& frames,
                                  const std::vector<Isometry3d>& poses,
                                  const PlaneExtractionOptions& options) {
  std::vector<Plane> planes;
  if (frames.size() != poses.size() || !valid_plane_extraction_options(options)) return planes;
  const plane_detail::WindowPoints window = plane_detail::place_points(frames, poses, options);
  const plane_detail::RootVoxels roots = plane_detail::group_by_voxel(window);
  const std::size_t n_voxels = roots.keys.size();
  std::vector<std::vector<Plane>> per_voxel(n_voxels);
  const double half = options.voxel_size / 2;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_voxels, plane_detail::kVoxelGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t v = r.begin(); v != r.end(); ++v) {
                        std::vector<std::uint32_t> cell(roots.members.begin() + roots.start[v],
                                                        roots.members.begin() + roots.start[v + 1]);
                        const Vec3d centre = ulc::voxel_corner(roots.keys[v], options.voxel_size) +
                                             Vec3d::Constant(half);
                        plane_detail::extract_cell(window.points, cell, centre, half, 0,
                                                   frames.size(), options, per_voxel[v]);
                      }
                    });
  for (auto& list : per_voxel)
    for (auto& p : list) planes.push_back(std::move(p));
  return planes;
}

}  // namespace hots
