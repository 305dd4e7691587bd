// Choosing the stretch of a long drive to calibrate on (not in the paper). What pins an extrinsic
// and a clock offset down is in turns, speed changes and structure, not in the drive's length;
// HOTS's memory and time grow with the frames it is given (docs/BENCHMARKS.md, "Long drives").
// On a drive longer than a budget, a survey runs first and one stretch of `budget_s` seconds is
// calibrated: the one whose motion and structure carry the most.
//
//   survey: the base LiDAR's single odometry (odometry.hpp) on coarsely thinned scans of its
//           frames at survey_rate_hz, frames handed over one at a time in time order
//           (DriveSurvey::add; nothing of a frame is kept but its pose, time and registration
//           conditioning)
//   windows: every stretch of budget_s seconds starting at a multiple of step_s from the first
//           frame (the last one ends at the drive's end), scored by
//             rotation_rad[i] = sum over survey steps of |rotation about body axis i|,
//             speed_change_mps = sum of |v_k - v_(k-1)| over the steps (body-frame velocities),
//             structure = the mean registration conditioning (registration_conditioning.hpp:
//                         the weakest direction's share; low in a tunnel or on a highway),
//           score = sum_i log(1 + rotation_rad[i] / rotation_scale_rad)
//                   + log(1 + speed_change_mps / speed_change_scale_mps)
//                   + log(1 + structure / structure_scale):
//           each term grows with what it carries and saturates, so a stretch with turns AND speed
//           changes AND structure beats one with plenty of only one of them. The scales are
//           orders of magnitude (a 6-degree turn, a 1 m/s speed change, the conditioning the
//           odometry accepts times ten), not fitted to any drive's answer.
//   choice: the highest score; ties go to the earlier stretch. Both LiDARs seeing common ground
//           is not scored (the survey runs on the base alone): JEEP's and HOTS's own checks
//           refuse a stretch without it.
//
// Deterministic: the survey is the odometry's (the same for any thread count) and the scoring is
// serial.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "odometry/odometry.hpp"
#include "odometry/scan_preparation.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

struct SelectionOptions {
  /// s of data calibrated on a longer drive; <= 0: the whole drive. 60 s: the drive length
  /// whose accuracy docs/BENCHMARKS.md holds (64-32: e_rot 0.0025 deg, e_trans 0.1 cm, offset
  /// exact) at a 1.3 GB peak ("Long drives"); memory grows with it (HOTS keeps its frames).
  double budget_s = 60.0;
  double step_s = 5.0;  ///< s between the starts of candidate stretches
  /// Base frames per second the survey registers: 2 Hz (5 m apart at 10 m/s, within the
  /// odometry's first gate of a constant-velocity prediction) reads a fifth of a 10 Hz drive.
  double survey_rate_hz = 2.0;
  double rotation_scale_rad = 0.1;
  double speed_change_scale_mps = 1.0;
  double structure_scale = 0.01;
  odometry::OdometryOptions survey = survey_odometry();  ///< the survey's odometry

  /// The odometry's defaults on scans thinned twice as much: the survey wants motion to a few
  /// centimetres and degrees, not the calibration's millimetres.
  static odometry::OdometryOptions survey_odometry() {
    odometry::OdometryOptions o;
    o.scan.map_voxel = 1.0;
    o.scan.registration_voxel = 2.0;
    return o;
  }
};

/// One candidate stretch and what it carries.
struct StretchScore {
  double start_s = 0.0, end_s = 0.0;   ///< seconds after the drive's first frame
  Vec3d rotation_rad = Vec3d::Zero();  ///< about the base's x, y, z
  double speed_change_mps = 0.0;
  double structure = 0.0;
  double score = 0.0;
};

struct Selection {
  bool applied = false;  ///< false: the drive fits the budget (or the survey failed; see why)
  double drive_s = 0.0;  ///< the drive's length
  double start_s = 0.0, end_s = 0.0;  ///< the chosen stretch, seconds after the first frame
  std::size_t chosen = 0;             ///< index into windows
  std::vector<StretchScore> windows;
  std::string why;
  double seconds = 0.0;  ///< the survey's time (set by the caller that timed it)
};

/// The survey of one drive: frames in, one at a time in time order (see the top).
template <typename S = float>
class DriveSurvey {
 public:
  /// `sweep_s`: the LiDAR's frame period (each frame is deskewed over it).
  DriveSurvey(const SelectionOptions& options, double sweep_s)
      : options_(options), sweep_s_(sweep_s), odometry_(options.survey) {}

  /// Frames the survey skips need not be read: false for a frame at `time` it will not use.
  bool wants(double time) const {
    return samples_.empty() || time - samples_.back().time >= 0.999 / options_.survey_rate_hz;
  }

  /// Registers `cloud` (per-point times relative to `time`) when wants(time).
  template <class Cloud>
  void add(const Cloud& cloud, double time) {
    if (!wants(time)) return;
    const auto scan =
        odometry::prepare_scan<S>(cloud, odometry_.twist(), sweep_s_, options_.survey.scan);
    const odometry::OdometryStep step = odometry_.step(scan, time, nullptr, time);
    samples_.push_back({time, step.pose_a, step.registered ? step.condition : 0.0});
  }

  std::size_t samples() const { return samples_.size(); }

  /// The stretches and the chosen one (see the top).
  Selection select(double first_time, double last_time) const {
    Selection s;
    s.drive_s = last_time - first_time;
    const double budget = options_.budget_s;
    if (!(budget > 0.0) || s.drive_s <= budget) {
      s.why = "the drive (" + seconds(s.drive_s) + ") fits the budget of " + seconds(budget);
      return s;
    }
    if (samples_.size() < 3) {
      s.why = "too few frames to survey the drive: the first " + seconds(budget) + " are used";
      s.end_s = budget;
      return s;
    }
    const double step = options_.step_s > 0.0 ? options_.step_s : budget;  // no endless loop
    for (std::size_t k = 0;; ++k) {
      const double begin = std::min(static_cast<double>(k) * step, s.drive_s - budget);
      s.windows.push_back(score(first_time + begin, first_time + begin + budget, first_time));
      if (begin >= s.drive_s - budget) break;
    }
    for (std::size_t k = 1; k < s.windows.size(); ++k)
      if (s.windows[k].score > s.windows[s.chosen].score) s.chosen = k;
    const StretchScore& best = s.windows[s.chosen];
    s.applied = true;
    s.start_s = best.start_s;
    s.end_s = best.end_s;
    s.why = "the drive (" + seconds(s.drive_s) + ") is longer than the budget of " +
            seconds(budget) + ": the best of " + std::to_string(s.windows.size()) +
            " candidate stretches for rotation about every axis, speed change and structure";
    return s;
  }

 private:
  struct Sample {
    double time;
    Isometry3d pose;
    double condition;
  };

  static std::string seconds(double s) {
    return std::to_string(static_cast<long long>(std::lround(s))) + " s";
  }

  StretchScore score(double t0, double t1, double origin) const {
    StretchScore w;
    w.start_s = t0 - origin;
    w.end_s = t1 - origin;
    Vec3d previous_velocity = Vec3d::Zero();
    bool has_previous = false;
    double condition_sum = 0.0;
    std::size_t conditions = 0;
    for (std::size_t k = 1; k < samples_.size(); ++k) {
      const Sample& a = samples_[k - 1];
      const Sample& b = samples_[k];
      if (a.time < t0 || b.time > t1) continue;
      const double dt = b.time - a.time;
      const Vec6d xi = se3_log(Isometry3d(a.pose.inverse() * b.pose));
      w.rotation_rad += xi.tail<3>().cwiseAbs();
      const Vec3d velocity = xi.head<3>() / dt;
      if (has_previous) w.speed_change_mps += (velocity - previous_velocity).norm();
      previous_velocity = velocity;
      has_previous = true;
      condition_sum += b.condition;
      ++conditions;
    }
    w.structure = conditions ? condition_sum / static_cast<double>(conditions) : 0.0;
    w.score = w.rotation_rad
                  .unaryExpr([&](double r) { return std::log1p(r / options_.rotation_scale_rad); })
                  .sum() +
              std::log1p(w.speed_change_mps / options_.speed_change_scale_mps) +
              std::log1p(w.structure / options_.structure_scale);
    return w;
  }

  SelectionOptions options_;
  double sweep_s_;
  odometry::Odometry<S> odometry_;
  std::vector<Sample> samples_;
};

}  // namespace ulc
