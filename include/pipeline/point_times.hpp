// Per-point times for a LiDAR whose frames carry none: the compiled entry calibrate_pair
// (pipeline/implementation.hpp) synthesises them from azimuth (ulc/core/sweep_times.hpp) when
// the LiDAR's first frame without times looks like a 360-degree sweep in firing order, on a copy
// of that LiDAR's frames from frame_index on (the frames before it stay empty: no stage reads
// them). Frames that do carry times are copied as they are. What could not be timed (a Livox
// pattern, a small-FoV unit, points not in firing order) reaches the pipeline without times,
// and pipeline/vouch.hpp bounds what that does to the translation.
//
// Frames read on demand (ulc/core/frame_source.hpp) go through a TimedSource instead: the first
// non-empty frame from frame_index decides (has times: every frame is handed over as read;
// none, and it looks like a sweep: every frame without times gets them from azimuth), and the
// report counts the frames the stages read, as they read them (no pass of its own over a drive).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "odometry/frame_pairing.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/pair_calibration.hpp"
#include "ulc/core/frame_source.hpp"
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

/// A FrameSource with per-point times synthesised where its frames have none (see the top).
class TimedSource : public FrameSource {
 public:
  TimedSource(const FrameSource& frames, const std::vector<double>& times, std::size_t first)
      : frames_(frames),
        period_(odometry::frame_period(times)),
        seen_(std::make_unique<std::atomic<std::uint8_t>[]>(frames.size())) {
    for (std::size_t k = 0; k < frames.size(); ++k) seen_[k] = kUnseen;
    for (std::size_t k = first; k < frames.size(); ++k) {
      const PointCloud<float> cloud = frames.load(k);
      if (cloud.empty()) continue;
      if (cloud.has_times()) return;
      const SweepTimes probe = sweep_times_from_azimuth(cloud, period_);
      synthesise_ = probe.ok();
      direction_ = probe.direction;
      reason_ = probe.reason;
      return;
    }
  }

  std::size_t size() const override { return frames_.size(); }

  PointCloud<float> load(std::size_t i) const override {
    PointCloud<float> cloud = frames_.load(i);
    if (cloud.empty() || cloud.has_times()) {
      seen_[i] = kTimed;
      return cloud;
    }
    SweepTimes t;
    if (synthesise_) t = sweep_times_from_azimuth(cloud, period_);
    if (synthesise_ && t.ok()) {
      cloud.times = std::move(t.times);
      seen_[i] = kSynthesised;
    } else {
      seen_[i] = kUntimed;
    }
    return cloud;
  }

  /// The frames without times among those read, and what was done about them.
  TimedFrames summary() const {
    TimedFrames out;
    for (std::size_t k = 0; k < frames_.size(); ++k) out.synthesised += seen_[k] == kSynthesised;
    out.direction = direction_;
    out.reason = reason_;
    return out;
  }

  /// The pipeline's report before synthesis (as point_times_of counts it).
  PointTimesReport untimed_report() const {
    std::size_t untimed = 0;
    for (std::size_t k = 0; k < frames_.size(); ++k) untimed += seen_[k] == kUntimed;
    PointTimesReport r;
    if (untimed == 0) return r;
    r.source = PointTimeSource::none;
    r.frames_without = untimed;
    r.note = std::to_string(untimed) +
             " frame(s) carry no per-point time: their sweeps are not deskewed";
    return r;
  }

 private:
  enum : std::uint8_t { kUnseen, kTimed, kUntimed, kSynthesised };
  const FrameSource& frames_;
  double period_;
  bool synthesise_ = false;
  int direction_ = 0;
  std::string reason_;
  std::unique_ptr<std::atomic<std::uint8_t>[]> seen_;
};

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
