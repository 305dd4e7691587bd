// Per-point times for a LiDAR whose frames carry none: the compiled entry calibrate_pair
// (pipeline/implementation.hpp) synthesises them from azimuth (ulc/core/sweep_times.hpp) when
// the LiDAR's first frame without times looks like a 360-degree sweep in firing order, on a copy
// of that LiDAR's frames from frame_index on (the frames before it stay empty: no stage reads
// them). Frames that do carry times are copied as they are. What could not be timed (a Livox
// pattern, a small-FoV unit, points not in firing order) reaches the pipeline without times,
// and pipeline/vouch.hpp bounds what that does to the translation.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "odometry/frame_pairing.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/pair_calibration.hpp"
#include "ulc/core/sweep_times.hpp"

namespace ulc {

/// The frames the pipeline reads for one LiDAR: its own, or a copy with synthesised times.
struct TimedFrames {
  const FloatFrames* frames = nullptr;
  FloatFrames storage;
  std::size_t synthesised = 0;  ///< frames given times from azimuth
  int direction = 0;            ///< spin, as sweep_times.hpp reads it
  std::string reason;           ///< why none could be synthesised (empty when some were)
};

/// See the top. `first` is frame_index.
inline void fill_point_times(const FloatFrames& frames, const std::vector<double>& times,
                             std::size_t first, TimedFrames& out) {
  out.frames = &frames;
  std::size_t k0 = first;
  while (k0 < frames.size() && (frames[k0].empty() || frames[k0].has_times())) ++k0;
  if (k0 >= frames.size()) return;  // every frame has times
  const double period = odometry::frame_period(times);
  const SweepTimes probe = sweep_times_from_azimuth(frames[k0], period);
  if (!probe.ok()) {
    out.reason = probe.reason;
    return;
  }
  out.direction = probe.direction;
  out.storage.resize(frames.size());
  for (std::size_t k = first; k < frames.size(); ++k) {
    out.storage[k] = frames[k];
    if (frames[k].empty() || frames[k].has_times()) continue;
    SweepTimes t = k == k0 ? probe : sweep_times_from_azimuth(frames[k], period);
    if (!t.ok()) continue;
    out.storage[k].times = std::move(t.times);
    ++out.synthesised;
  }
  out.frames = &out.storage;
}

/// The pipeline's point-time report for that LiDAR, with what the entry did.
inline void report_point_times(const TimedFrames& t, PointTimesReport& r) {
  if (t.synthesised > 0) {
    const std::size_t untimed = r.frames_without;
    r.frames_without += t.synthesised;
    r.source = untimed > 0 ? PointTimeSource::none : PointTimeSource::synthesised_from_azimuth;
    r.note = std::to_string(r.frames_without) +
             " frame(s) carry no per-point time: times synthesised from each point's azimuth (" +
             (t.direction < 0 ? "clockwise" : "counter-clockwise") + " spin)" +
             (untimed > 0 ? "; " + r.note : std::string());
  } else if (!t.reason.empty()) {
    r.note += " (no times from azimuth: " + t.reason + ")";
  }
}

}  // namespace ulc
