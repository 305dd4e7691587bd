// One LiDAR's sequence as the stages hand it on: its frames, their timestamps and, once an
// odometry has run, their poses. The frames are a view (any random-access container of clouds
// with point traits, or a FrameRange over one), so a sequence is cheap to pass and to copy.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "ulc/core/frame_range.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

template <class Frames>
struct LidarSequence {
  Frames frames;                  ///< per-point times relative to each frame's timestamp
  std::vector<double> times;      ///< seconds, one per frame (the base's clock inside the pipeline)
  std::vector<Isometry3d> poses;  ///< T_map_lidar at each timestamp; empty before the odometry

  std::size_t size() const { return times.size(); }
  bool has_poses() const { return !poses.empty() && poses.size() == times.size(); }
};

/// A sequence over `frames` (not copied: they must outlive it) from frame 0.
template <class Frames>
LidarSequence<FrameRange<Frames>> make_sequence(const Frames& frames, std::vector<double> times,
                                                std::vector<Isometry3d> poses = {}) {
  return {FrameRange<Frames>(frames, 0), std::move(times), std::move(poses)};
}

}  // namespace ulc
