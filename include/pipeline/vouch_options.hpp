// The options of the checks on what the data cannot vouch for (pipeline/vouch.hpp): a clock
// offset nobody estimated, frames without per-point times, and a covariance wider than a
// success allows (pipeline/confidence.hpp). Light: no algorithm.
#pragma once

#include <cstddef>

#include "ulc/core/pose_error.hpp"

namespace ulc {

/// The lag search of motion_lag.hpp.
struct MotionLagOptions {
  /// The lag is searched within +- this (s).
  double max_lag_s = 0.25;
  double step_s = 0.001;  ///< grid of the search before its parabola refinement (s)
  /// The motions compared: rotation rates and velocities over this baseline (s), normalised by
  /// noise levels no smaller than these floors. The rate floor is high on purpose: a straight
  /// drive's rates are its bumps' pitch and roll, which the two LiDARs' frames alias
  /// differently; only turns (0.1-0.5 rad/s) should count.
  double baseline_s = 0.6;
  double rate_noise = 0.03;      ///< rad/s
  double velocity_noise = 0.03;  ///< m/s
};

struct VouchOptions {
  /// How far an unestimated clock offset, or a sweep that could not be deskewed, may move the
  /// translation before the result stops being a success (m). Half the 10 cm of a success
  /// (the paper's threshold) leaves the rest to the registration itself; the benchmark
  /// bench_clocks measures both sides (docs/experiments/unestimated_clocks.md).
  double max_translation_effect_m = 0.05;
  /// The lag search between the two LiDARs' motions (motion_lag.hpp); its max_lag_s is also
  /// what "any plausible offset" means for a slow rig.
  MotionLagOptions lag;
  /// Seconds of each LiDAR's frames (from frame_index) whose single-LiDAR odometries give the
  /// motions the lag is estimated from: long enough to hold a turn.
  double lag_window_s = 30.0;
  /// The lag counts as bounded when (|lag| + sigma_factor * sigma) * speed is within
  /// max_translation_effect_m.
  double sigma_factor = 3.0;
  /// A HOTS success whose covariance gives it more than max_beyond_probability of lying beyond
  /// a success's own bars along its loosest direction becomes `uncertain`
  /// (pipeline/confidence.hpp).
  double success_translation_m = kCalibrationMaxTranslationM;
  double success_rotation_deg = kCalibrationMaxRotationDeg;
  double max_beyond_probability = 0.05;
  /// A success that is JEEP's answer becomes `uncertain` when its two directions (jeep/two_way.hpp)
  /// end farther apart than a success's own bars (pipeline/confidence.hpp).
  bool judge_two_way_gap = true;
  bool enabled = true;  ///< false: no check (the result still says the offset was not estimated)
};

}  // namespace ulc
