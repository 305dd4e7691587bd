// Loading only the frames `ulc calibrate` needs: TERRA reads frame i of each LiDAR; JEEP pairs
// frames by timestamp from frame i on and uses the first K pairs, so it needs K frames of the
// base and the target frames spanning the same time (more of them when the target runs faster);
// HOTS uses every frame from i on.
// Frames are read as ulc::PointCloud<float> with per-point times relative to the frame.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "jeep/frame_pairing.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/io/sequence.hpp"

namespace ulc::app {

struct LoadedFrames {
  std::vector<PointCloud<float>> clouds;
  std::vector<double> times;  ///< seconds, the LiDAR's own clock
};

/// Frames first .. first + count - 1 (fewer when the sequence ends first).
inline LoadedFrames load_frames(const io::Sequence& seq, std::size_t first, std::size_t count) {
  LoadedFrames out;
  const std::size_t end = std::min(seq.size(), first + count);
  for (std::size_t i = first; i < end; ++i) {
    auto frame = seq.load_frame<PointCloud<float>>(i);
    out.clouds.push_back(std::move(frame.cloud));
    out.times.push_back(frame.timestamp);
  }
  return out;
}

/// Median frame period of a sequence from its listed timestamps (0 for a single frame).
inline double sequence_period(const io::Sequence& seq) {
  std::vector<double> t;
  for (const auto& f : seq.frames()) t.push_back(f.timestamp);
  return jeep::frame_period(t);
}

/// How many target frames cover the time of `base_count` base frames, plus one for the edges.
inline std::size_t covering_count(const io::Sequence& base, const io::Sequence& target,
                                  std::size_t base_count) {
  const double pa = sequence_period(base), pb = sequence_period(target);
  if (!(pa > 0.0 && pb > 0.0)) return base_count + 1;
  return static_cast<std::size_t>(std::ceil(static_cast<double>(base_count) * pa / pb)) + 1;
}

/// UsageError unless frame `index` exists in `seq`.
inline void require_frame(const io::Sequence& seq, std::size_t index) {
  if (index >= seq.size())
    throw cli::UsageError("calibrate: --frame-index " + std::to_string(index) +
                          " is past the end of " + seq.path().string() + " (" +
                          std::to_string(seq.size()) + (seq.size() == 1 ? " frame)" : " frames)"));
}

}  // namespace ulc::app
