// What the data cannot vouch for: two ways a moving rig's translation goes wrong while every
// stage reports success, checked after the stages (docs/pipeline.md, "Clocks and point times").
//
//   - A clock offset nobody estimated. Without HOTS's time synchronisation and without a known
//     offset (CalibrateOptions::time_offset_s), JEEP pairs frames by their own clocks: an
//     offset d moves the translation by d times the target's speed (50 ms at 7.4 m/s: 37 cm),
//     and JEEP's maps still agree. The check (VouchOptions): the speed over JEEP's frames; if
//     no plausible offset (lag.max_lag_s) can move the translation by more than
//     max_translation_effect_m, "slow". Otherwise the lag between the two LiDARs' motions
//     (motion_lag.hpp, single-LiDAR odometries over lag_window_s of frames from frame_index):
//     (|lag| + sigma_factor sigma) * speed within the bar: "lag_within_bar", ok; a lag whose
//     effect exceeds the bar: "lag_exceeds_bar"; a drive that cannot bound it (no turn):
//     "lag_unobservable". Both of the last end with status time_offset_unestimated. The lag is
//     reported, never applied: HOTS (or a given offset) is what estimates an offset.
//   - Frames without per-point times. A sweep that is not deskewed sits, on average, half a
//     frame period late: the translation moves by up to speed * period / 2 (8.4 m/s at 10 Hz:
//     42 cm). A LiDAR whose frames (from frame_index) lack times is reported; when JEEP ran and
//     that bound exceeds max_translation_effect_m, status point_times_missing. (The compiled
//     entry, calibrate_pair, first synthesises times from azimuth for spinning LiDARs:
//     pipeline/point_times.hpp; what it could not time is what reaches this check.)
//   - A covariance wider than a success allows: more than a 5 % chance of lying beyond 10 cm or
//     1 deg along some direction, status uncertain (confidence.hpp).
//   - A rig the stillness check found parked (stillness.hpp): no offset and no sweep moves its
//     extrinsic; the clock's verdict is "parked" and a LiDAR without point times is named only.
//   Every result whose translation JEEP or HOTS made has a ClockReport (PairCalibration::clock)
//   saying where the offset came from and, when not estimated, how far 1 ms moves the answer.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "odometry/frame_pairing.hpp"
#include "odometry/run_odometry.hpp"
#include "pipeline/attempt.hpp"
#include "pipeline/confidence.hpp"
#include "pipeline/motion_lag.hpp"
#include "pipeline/pair_calibration.hpp"
#include "pipeline/text_format.hpp"
#include "ulc/core/point_traits.hpp"

namespace ulc {
namespace calibrate_detail {

/// per_point, or none with the count of frames that lack times.
template <class Frames>
PointTimesReport point_times_of(const Frames& frames) {
  PointTimesReport r;
  for (std::size_t k = 0; k < frames.size(); ++k)
    if (traits::size(frames[k]) > 0 && !traits::has_time(frames[k])) ++r.frames_without;
  if (r.frames_without > 0) {
    r.source = PointTimeSource::none;
    r.note = std::to_string(r.frames_without) +
             " frame(s) carry no per-point time: their sweeps are not deskewed";
  }
  return r;
}

/// The first frames of a view, up to a count: the lag check's window.
template <class Frames>
struct FirstFrames {
  const Frames* frames;
  std::size_t count;
  std::size_t size() const { return count; }
  decltype(auto) operator[](std::size_t i) const { return (*frames)[i]; }
};

/// Frames whose timestamps lie within `seconds` of the first.
inline std::size_t frames_within(const std::vector<double>& times, double seconds) {
  std::size_t n = 0;
  while (n < times.size() && times[n] - times.front() <= seconds) ++n;
  return n;
}

/// Each LiDAR's own odometry over the window, then the lag between their motions
/// (motion_lag.hpp: rotation rates and speeds).
template <class FA, class FB>
MotionLag motion_lag(const AttemptInputs<FA, FB>& in, const Isometry3d& T_ab) {
  const VouchOptions& v = in.options.tuning.vouch;
  const std::size_t na = frames_within(in.a.times, v.lag_window_s);
  const std::size_t nb = frames_within(in.b.times, v.lag_window_s);
  if (na < 4 || nb < 4) return {};
  const std::vector<double> ta(in.a.times.begin(), in.a.times.begin() + static_cast<long>(na));
  const std::vector<double> tb(in.b.times.begin(), in.b.times.begin() + static_cast<long>(nb));
  using ViewA = std::decay_t<decltype(in.a.frames)>;
  using ViewB = std::decay_t<decltype(in.b.frames)>;
  const auto odo_a = odometry::run_single_odometry(FirstFrames<ViewA>{&in.a.frames, na}, ta,
                                                   in.options.tuning.odometry);
  const auto odo_b = odometry::run_single_odometry(FirstFrames<ViewB>{&in.b.frames, nb}, tb,
                                                   in.options.tuning.odometry);
  if (odo_a.poses_a.empty() || odo_b.poses_a.empty()) return {};
  return estimate_motion_lag(odo_a.poses_a, ta, odo_b.poses_a, tb, T_ab, v.lag);
}

/// The clock's verdict on a JEEP translation with no offset estimated or given (see the top).
template <class FA, class FB>
ClockReport unestimated_clock(const AttemptInputs<FA, FB>& in, const PairCalibration& r) {
  const VouchOptions& v = in.options.tuning.vouch;
  ClockReport c;
  c.speed_mps = r.jeep->target_speed_mps;
  c.translation_per_ms_m = 0.001 * c.speed_mps;
  const std::string sensitivity = "an offset of 1 ms moves the translation by " +
                                  cm(c.translation_per_ms_m) + " at this drive's speed of " +
                                  fixed(c.speed_mps, 2) + " m/s";
  const std::string head =
      "the clock offset was not estimated (no HOTS time synchronisation, no "
      "known offset): " +
      sensitivity;
  if (!v.enabled) {
    c.verdict = "unchecked";
    c.note = head;
    return c;
  }
  if (in.parked()) {
    c.verdict = "parked";
    c.note = "the clock offset was not estimated, and need not be: " + in.base.stillness->reason +
             ", so no offset moves the extrinsic";
    return c;
  }
  if (c.speed_mps * v.lag.max_lag_s <= v.max_translation_effect_m) {
    c.verdict = "slow";
    c.note = head + "; even " + fixed(v.lag.max_lag_s * 1000.0, 0) + " ms would move it by " +
             cm(c.speed_mps * v.lag.max_lag_s) + " at most";
    return c;
  }
  const MotionLag lag = motion_lag(in, r.T_base_target);
  c.lag_checked = lag.samples > 0;
  c.lag_s = lag.lag_s;
  c.lag_sigma_s = lag.sigma_s;
  c.lag_samples = lag.samples;
  const std::size_t window = frames_within(in.a.times, v.lag_window_s);
  c.lag_window_s = window > 0 ? in.a.times[window - 1] - in.a.times.front() : 0.0;
  const double bound = (std::abs(lag.lag_s) + v.sigma_factor * lag.sigma_s) * c.speed_mps;
  const std::string found = "the LiDARs' motions lag by " + fixed(lag.lag_s * 1000.0, 1) + " +- " +
                            fixed(lag.sigma_s * 1000.0, 1) + " ms";
  if (c.lag_checked && bound <= v.max_translation_effect_m) {
    c.verdict = "lag_within_bar";
    c.note = head + "; " + found + ", which moves it by " + cm(bound) + " at most";
  } else if (c.lag_checked && std::abs(lag.lag_s) > v.sigma_factor * lag.sigma_s &&
             std::abs(lag.lag_s) * c.speed_mps > v.max_translation_effect_m) {
    c.verdict = "lag_exceeds_bar";
    c.note = head + "; " + found + ": that moves the translation by about " +
             cm(std::abs(lag.lag_s) * c.speed_mps);
  } else {
    c.verdict = "lag_unobservable";
    c.note = head + "; the " + fixed(c.lag_window_s, 1) +
             " s of frames checked do not bound the lag (" +
             (c.lag_checked ? found : std::string("too few frames to compare")) +
             "; turns and speed changes show it)";
  }
  return c;
}

/// Where the result's clock offset comes from, and its verdict when nobody estimated it.
template <class FA, class FB>
ClockReport clock_report(const AttemptInputs<FA, FB>& in, const PairCalibration& r) {
  ClockReport c;
  const bool hots_answer = r.hots_refined();
  if (in.options.time_offset_s) {
    c.source = ClockSource::given;
    c.note = "the clock offset was given (" + fixed(*in.options.time_offset_s, 4) + " s)";
  } else if (hots_answer && (in.hots.synchronise_time || in.hots.sequence.estimate_time_offset)) {
    c.source = ClockSource::estimated_by_hots;
    c.note = "the clock offset was estimated by HOTS";
  } else if (r.jeep && !hots_answer) {
    c = unestimated_clock(in, r);
  } else {
    c.note = "the clock offset was not estimated (HOTS ran without its time synchronisation)";
  }
  return c;
}

/// A LiDAR without point times, when JEEP's speed says how far its sweeps move the answer:
/// the reason to refuse, or empty. A parked rig's sweeps have no motion to undo.
inline std::string undeskewed_sweep(const char* which, PointTimesReport& p, double period,
                                    const PairCalibration& r, const VouchOptions& v, bool parked) {
  if (p.source != PointTimeSource::none || !r.jeep) return "";
  if (parked) {
    p.note += "; the rig stood still: its sweeps have no motion to undo";
    return "";
  }
  const double bound = r.jeep->target_speed_mps * period / 2.0;
  const std::string effect = "at this drive's speed of " + fixed(r.jeep->target_speed_mps, 2) +
                             " m/s and a " + fixed(period * 1000.0, 0) +
                             " ms sweep they move the translation by up to " + cm(bound);
  p.note += "; " + effect;
  if (bound <= v.max_translation_effect_m) return "";
  return std::string("the ") + which + " LiDAR's frames carry no per-point time and are not a " +
         "360-degree sweep whose times follow from azimuth: " + effect +
         "; record the driver's per-point time field";
}

/// The checks on a successful result (see the top): its status and reason, changed when the
/// data cannot vouch for its translation.
template <class FA, class FB>
StageOutcome vouch(const AttemptInputs<FA, FB>& in, PairCalibration& r) {
  const StageOutcome kept{r.status, r.reason, false};
  if (!r.success) return kept;
  const VouchOptions& v = in.options.tuning.vouch;
  for (auto [which, report, times] :
       {std::make_tuple("base", &r.point_times_base, &in.a.times),
        std::make_tuple("target", &r.point_times_target, &in.b.times)}) {
    const std::string why =
        undeskewed_sweep(which, *report, odometry::frame_period(*times), r, v, in.parked());
    if (!why.empty()) return {CalibrateStatus::point_times_missing, why, false};
  }
  if (!r.jeep && !r.hots_refined()) return kept;  // TERRA's rotation
  r.clock = clock_report(in, r);
  if (r.clock->verdict == "lag_exceeds_bar" || r.clock->verdict == "lag_unobservable")
    return {CalibrateStatus::time_offset_unestimated,
            r.clock->note +
                "; run HOTS (--stages terra,jeep,hots) or give the offset (--synced-clocks, "
                "--time-offset S)",
            false};
  if (std::string why = loosely_pinned(r, v); !why.empty())
    return {CalibrateStatus::uncertain, std::move(why), false};
  if (std::string why = directions_disagree(r, v); !why.empty())
    return {CalibrateStatus::uncertain, std::move(why), false};
  return kept;
}

}  // namespace calibrate_detail
}  // namespace ulc
