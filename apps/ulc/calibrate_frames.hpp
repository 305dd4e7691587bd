// How many frames `ulc calibrate` loads: TERRA reads frame i of each LiDAR; JEEP pairs frames by
// timestamp from frame i on and uses the first K pairs, so it needs K frames of the base and the
// target frames spanning the same time (more of them when the target runs faster); HOTS uses
// every frame from i on.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include "lidar_input.hpp"
#include "pipeline/options.hpp"
#include "usage_error.hpp"

namespace ulc::app {

/// How many target frames cover the time of `base_count` base frames, plus one for the edges.
inline std::size_t covering_count(double base_period, double target_period,
                                  std::size_t base_count) {
  if (!(base_period > 0.0 && target_period > 0.0)) return base_count + 1;
  return static_cast<std::size_t>(
             std::ceil(static_cast<double>(base_count) * base_period / target_period)) +
         1;
}

/// The base's frames JEEP alone reads: its K frames, or, when no offset is given or estimated
/// (no HOTS, no --synced-clocks / --time-offset), enough for the clock check's lag window
/// (pipeline/vouch.hpp: the lag between the LiDARs' motions needs a turn).
inline std::size_t jeep_only_count(const CalibrateOptions& options, double base_period) {
  const std::size_t k = options.tuning.jeep.frames;
  const VouchOptions& v = options.tuning.vouch;
  if (options.time_offset_s || !v.enabled) return k;
  const double period = base_period > 0.0 ? base_period : options.tuning.jeep.default_period;
  return std::max(k, static_cast<std::size_t>(std::ceil(v.lag_window_s / period)) + 1);
}

/// UsageError unless frame `index` was there to load.
inline void require_frame(const LidarInput& input, const StreamedFrames& frames,
                          std::size_t index) {
  if (frames.times.empty())
    throw UsageError("calibrate: --frame-index " + std::to_string(index) +
                     " is past the last frame of " + input.source());
}

}  // namespace ulc::app
