// run_odometry: multi-LiDAR (or single-LiDAR) odometry over whole frame sequences, giving the
// pose of every frame of both LiDARs (conventions: odometry.hpp).
//
//   - Input: frames of each LiDAR (any random-access container of traits clouds, per-point
//     times relative to each frame's timestamp), their timestamps (seconds, own clocks) and,
//     for two LiDARs, the extrinsic C = T_base_target.
//   - Pairs: frame_pairing.hpp with max gap options.max_pair_gap * a's frame period.
//   - Each pair: both scans prepared (deskewed with the current twist over one frame period of
//     their LiDAR, downsampled), then one Odometry step. Frames are loaded and dropped one pair
//     at a time: memory is bounded by the maps.
//   - Output poses: P_a for every a frame (T_mapa_a at its timestamp) and P_b for every b frame
//     (T_mapb_b at its timestamp); paired frames carry their step's estimate, the others are
//     extrapolated from the nearest pair in time with that pair's twist.
//   - Status: ok; invalid_input (bad options, timestamps or extrinsic, or frame and timestamp
//     counts that differ); no_pairs (nothing to pair); registration_failed when any step kept its
//     guess (failed_steps counts them; the poses are still filled in).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <optional>
#include <type_traits>
#include <vector>

#include "odometry/frame_pairing.hpp"
#include "odometry/odometry.hpp"
#include "odometry/scan_preparation.hpp"
#include "odometry/status.hpp"
#include "ulc/core/median.hpp"
#include "ulc/core/point_traits.hpp"

namespace odometry {

struct OdometryResult {
  OdometryStatus status = OdometryStatus::ok;
  const char* reason = "";
  std::vector<FramePair> pairs;     ///< single-LiDAR: b == a
  std::vector<OdometryStep> steps;  ///< one per pair
  std::vector<Isometry3d> poses_a;  ///< one per a frame: T_mapa_a at its timestamp
  std::vector<bool> estimated_a;    ///< false: extrapolated (unpaired frame)
  std::vector<Isometry3d> poses_b;  ///< one per b frame: T_mapb_b (empty for one LiDAR)
  std::vector<bool> estimated_b;
  std::size_t failed_steps = 0;

  bool ok() const { return status == OdometryStatus::ok; }
};

/// The median condition of the registered steps (OdometryStep::condition: the weakest direction's
/// share of the strongest in the scaled registration problem); 0 when none registered. In a
/// tunnel or on a straight road with rails it is about 0.003-0.014, on the other simulated drives
/// 0.067-0.20 (docs/experiments/degenerate_scenes.md): the odometry then follows its motion
/// model along the free direction, and motion-derived quantities inherit that.
inline double median_condition(const OdometryResult& odo) {
  std::vector<double> c;
  for (const OdometryStep& s : odo.steps)
    if (s.registered) c.push_back(s.condition);
  return ulc::upper_median(std::move(c));
}

using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

namespace detail {

template <class Frames>
using frame_cloud_t = std::decay_t<decltype(std::declval<const Frames&>()[0])>;

/// Index of the step whose a time is nearest to t (steps sorted by time; ties: earlier).
inline std::size_t nearest_step(const std::vector<OdometryStep>& steps, double t) {
  const auto it = std::lower_bound(steps.begin(), steps.end(), t,
                                   [](const OdometryStep& s, double v) { return s.t_a < v; });
  std::size_t k = static_cast<std::size_t>(it - steps.begin());
  if (k == steps.size() || (k > 0 && t - steps[k - 1].t_a <= steps[k].t_a - t)) --k;
  return k;
}

inline Isometry3d extrapolate(const OdometryStep& s, double t) {
  return s.pose_a * ulc::se3_exp(Vec6d((t - s.t_a) * s.twist));
}

/// Why the odometry cannot run; nullptr when it can.
template <class FramesA, class FramesB>
const char* input_problem(const FramesA& frames_a, const std::vector<double>& times_a,
                          const FramesB* frames_b, const std::vector<double>* times_b,
                          const std::optional<Isometry3d>& C, const OdometryOptions& options) {
  if (!valid_odometry_options(options)) return "bad options";
  if (frames_a.size() != times_a.size() || (frames_b && frames_b->size() != times_b->size()))
    return "frame and timestamp counts differ";
  if (!timestamps_usable(times_a) || (times_b && !timestamps_usable(*times_b)))
    return "timestamps not finite and nondecreasing";
  if (C && !C->matrix().allFinite()) return "extrinsic not finite";
  return nullptr;
}

/// One step per frame pair (a alone: one per frame), each scan deskewed with the current twist.
template <typename S, class FramesA, class FramesB>
void run_steps(const FramesA& frames_a, const std::vector<double>& times_a, const FramesB* frames_b,
               const std::vector<double>* times_b, const OdometryOptions& options,
               const ProgressFn& progress, Odometry<S>& odometry, OdometryResult& result) {
  const double period_a = frame_period(times_a);
  const double period_b = times_b ? frame_period(*times_b) : period_a;
  for (std::size_t k = 0; k < result.pairs.size(); ++k) {
    const FramePair& pair = result.pairs[k];
    const Vec6d xi = odometry.twist();
    const auto scan_a = prepare_scan<S>(frames_a[pair.a], xi, period_a, options.scan);
    if (frames_b) {
      const auto scan_b =
          prepare_scan<S>((*frames_b)[pair.b], odometry.target_twist(xi), period_b, options.scan);
      result.steps.push_back(odometry.step(scan_a, times_a[pair.a], &scan_b,
                                           (*times_b)[pair.b] + options.time_offset_s));
    } else {
      result.steps.push_back(odometry.step(scan_a, times_a[pair.a], nullptr, times_a[pair.a]));
    }
    if (k > 0 && !result.steps.back().registered) ++result.failed_steps;
    if (progress) progress(k + 1, result.pairs.size());
  }
}

/// The steps' poses at the timestamps from the mid-sweep poses and central-difference twists
/// (better than the steps' backward ones), re-expressed in a's frame at its first timestamp.
template <typename S>
void settle_step_poses(const Odometry<S>& odometry, const std::optional<Isometry3d>& C,
                       std::vector<OdometryStep>& steps) {
  std::vector<Isometry3d> mids;
  std::vector<double> mid_times;
  for (const OdometryStep& s : steps) {
    mids.push_back(s.mid_pose_a);
    mid_times.push_back(s.mid_time);
  }
  const auto twists = twists_from_mid_poses(mids, mid_times, steps[0].twist);
  for (std::size_t k = 0; k < steps.size(); ++k) {
    OdometryStep& s = steps[k];
    s.twist = twists[k];
    s.pose_a = s.mid_pose_a * ulc::se3_exp(Vec6d((s.t_a - s.mid_time) * s.twist));
    if (C) s.pose_b = odometry.target_pose(s.pose_a, s.t_a, s.t_b, s.twist);
  }
  const Isometry3d to_first = steps[0].pose_a.inverse();
  const Isometry3d to_first_b = C ? Isometry3d(C->inverse() * to_first * *C) : to_first;
  for (OdometryStep& s : steps) {
    s.pose_a = to_first * s.pose_a;
    s.mid_pose_a = to_first * s.mid_pose_a;
    s.scan_pose_a = to_first * s.scan_pose_a;
    s.pose_b = to_first_b * s.pose_b;
    s.scan_pose_b = to_first_b * s.scan_pose_b;
  }
}

/// A pose for every frame: the paired frames their step's, the others extrapolated from the
/// nearest step in time with its twist.
template <typename S>
void frame_poses(const Odometry<S>& odometry, const std::vector<double>& times_a,
                 const std::vector<double>* times_b, const OdometryOptions& options,
                 OdometryResult& result) {
  result.poses_a.resize(times_a.size());
  result.estimated_a.assign(times_a.size(), false);
  for (std::size_t i = 0; i < times_a.size(); ++i)
    result.poses_a[i] =
        extrapolate(result.steps[nearest_step(result.steps, times_a[i])], times_a[i]);
  for (std::size_t k = 0; k < result.pairs.size(); ++k) {
    result.poses_a[result.pairs[k].a] = result.steps[k].pose_a;
    result.estimated_a[result.pairs[k].a] = true;
  }
  if (!times_b) return;
  result.poses_b.resize(times_b->size());
  result.estimated_b.assign(times_b->size(), false);
  for (std::size_t j = 0; j < times_b->size(); ++j) {
    const double t = (*times_b)[j] + options.time_offset_s;
    const OdometryStep& s = result.steps[nearest_step(result.steps, t)];
    result.poses_b[j] = odometry.target_pose(s.pose_a, s.t_a, t, s.twist);
  }
  for (std::size_t k = 0; k < result.pairs.size(); ++k) {
    result.poses_b[result.pairs[k].b] = result.steps[k].pose_b;
    result.estimated_b[result.pairs[k].b] = true;
  }
}

template <class FramesA, class FramesB, typename S>
OdometryResult run(const FramesA& frames_a, const std::vector<double>& times_a,
                   const FramesB* frames_b, const std::vector<double>* times_b,
                   const std::optional<Isometry3d>& C, const OdometryOptions& options,
                   const ProgressFn& progress) {
  OdometryResult result;
  auto fail = [&](OdometryStatus s, const char* why) {
    result.status = s;
    result.reason = why;
    return result;
  };
  if (const char* why = input_problem(frames_a, times_a, frames_b, times_b, C, options))
    return fail(OdometryStatus::invalid_input, why);
  if (frames_b) {
    result.pairs = pair_frames(times_a, *times_b, options.time_offset_s,
                               options.max_pair_gap * frame_period(times_a));
  } else {
    for (std::size_t i = 0; i < times_a.size(); ++i) result.pairs.push_back({i, i});
  }
  if (result.pairs.empty()) return fail(OdometryStatus::no_pairs, "no frames to pair");
  Odometry<S> odometry(options, C);
  run_steps<S>(frames_a, times_a, frames_b, times_b, options, progress, odometry, result);
  settle_step_poses(odometry, C, result.steps);
  frame_poses(odometry, times_a, frames_b ? times_b : nullptr, options, result);
  if (result.failed_steps > 0)
    return fail(OdometryStatus::registration_failed,
                "some frames could not be registered (too few correspondences); their poses are "
                "predictions");
  return result;
}

}  // namespace detail

/// Multi-LiDAR odometry: base frames a, target frames b, extrinsic C = T_base_target.
template <class FramesA, class FramesB>
OdometryResult run_odometry(const FramesA& frames_a, const std::vector<double>& times_a,
                            const FramesB& frames_b, const std::vector<double>& times_b,
                            const Isometry3d& C, const OdometryOptions& options = {},
                            const ProgressFn& progress = {}) {
  using S = ulc::traits::scalar_t<detail::frame_cloud_t<FramesA>>;
  return detail::run<FramesA, FramesB, S>(frames_a, times_a, &frames_b, &times_b, C, options,
                                          progress);
}

/// Single-LiDAR odometry: every frame is a step.
template <class Frames>
OdometryResult run_single_odometry(const Frames& frames, const std::vector<double>& times,
                                   const OdometryOptions& options = {},
                                   const ProgressFn& progress = {}) {
  using S = ulc::traits::scalar_t<detail::frame_cloud_t<Frames>>;
  return detail::run<Frames, Frames, S>(frames, times, nullptr, nullptr, std::nullopt, options,
                                        progress);
}

/// A single-LiDAR odometry of base a carried to target b through the rigid mount: b's poses
/// P_b(t_b) = C^-1 P_a(t_b) C, P_a(t_b) extrapolated from a's step nearest t_b (b's timestamps
/// plus time_offset_s, on a's clock) with its twist; the poses and steps of a are kept. This is
/// what the multi-LiDAR odometry does for every b frame it did not pair, done for all of them.
inline OdometryResult with_target_poses(OdometryResult base, const std::vector<double>& times_b,
                                        const Isometry3d& C, double time_offset_s = 0.0) {
  if (base.steps.empty()) return base;
  const Isometry3d C_inv = C.inverse();
  base.poses_b.resize(times_b.size());
  base.estimated_b.assign(times_b.size(), false);
  for (std::size_t j = 0; j < times_b.size(); ++j) {
    const double t = times_b[j] + time_offset_s;
    base.poses_b[j] =
        C_inv * detail::extrapolate(base.steps[detail::nearest_step(base.steps, t)], t) * C;
  }
  return base;
}

}  // namespace odometry
