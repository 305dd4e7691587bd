// Which odometry gives HOTS its starting poses when the caller leaves it to the pipeline
// (StageTuning::hots_odometry automatic): the base's own on a long drive of a base that sees all
// around, the joint one otherwise.
//
// Conventions this header owns:
//   - The base's own odometry (HotsOdometry::base) depends neither on the target nor on the
//     extrinsic, so one run serves every TERRA hypothesis and every target of a rig: 2.6 times
//     cheaper than the joint one on the 60 s 64-32 drive, and the rig's six targets share it.
//     The joint odometry's gain is where the base alone holds its poses loosely: a narrow base
//     (the Horizon of horizon-tele), and short drives, where a few frames of target structure
//     steady the poses (10 s drives: 32-avia seed 2 uncertain, 32-mid40 seed 1 0.012 -> 0.032
//     deg; docs/experiments/hots_base_odometry.md).
//   - Rule: base when the base's frames from frame_index last at least min_duration_s seconds
//     (their span and one frame period: 300 frames at 10 Hz last 30 s) and the base sees
//     all around, else joint. min_duration_s = 30 s: on the paper's pairs with a
//     360-degree base, 30 s and 60 s drives gave the same answers with either odometry
//     (docs/experiments/hots_base_odometry.md, "Longer drives").
//   - "Sees all around": at least min_azimuth_coverage of the azimuth_sectors sectors of equal
//     angle about the LiDAR's own z axis hold a point at least min_range_m away (nearer points
//     are the vehicle itself), in the median of three frames (the first, the middle and the
//     last of the stretch). A spinning LiDAR covers every sector; a Horizon (81.7 deg) or an
//     Avia (70.4 deg) at most a quarter. The rule looks only at the base's frames, so every
//     target of a rig gets the same choice and shares the base's work (rig.hpp).
//   - When the automatic choice's base odometry ends without a success (refused, uncertain,
//     failed), the stages after TERRA run again on the joint odometry and that result is the
//     call's: every drive the joint odometry calibrates is still calibrated (64-tele,
//     60 s: the base's odometry gave the right answer but a covariance of 6.1 cm along y,
//     uncertain; the joint one 2.9 cm, ok). The refusals cost both runs. A static rig
//     (parked, or too few frames for HOTS) runs no odometry: its stages run once.
//   - `why` says, in one sentence, which was chosen and why; the result file reports both
//     (stages.hots.odometry, odometry_choice).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include "odometry/frame_pairing.hpp"
#include "pipeline/options.hpp"
#include "ulc/core/point_traits.hpp"

namespace ulc {

/// The odometry chosen and why.
struct OdometryChoice {
  HotsOdometry odometry = HotsOdometry::joint;
  std::string why;
  /// The automatic choice took the base's odometry: when the call ends without a success, its
  /// stages run again on the joint odometry (pipeline.hpp).
  bool joint_if_refused = false;
};

/// The joint odometry after the automatic choice's base odometry ended without a success.
inline OdometryChoice joint_after_refusal(const OdometryChoice& first, const std::string& status,
                                          const std::string& reason) {
  return {HotsOdometry::joint,
          "joint: the base's own odometry was tried first (" + first.why + ") and ended " + status +
              (reason.empty() ? "" : ": " + reason),
          false};
}

/// The share of azimuth sectors about the cloud's z axis that hold a point at least
/// options.min_range_m away horizontally.
template <class Cloud>
double azimuth_coverage(const Cloud& cloud, const OdometryChoiceOptions& options) {
  const std::size_t sectors = std::max<std::size_t>(options.azimuth_sectors, 1);
  std::vector<char> filled(sectors, 0);
  const double min_range_sq = options.min_range_m * options.min_range_m;
  const double per_radian = static_cast<double>(sectors) / 6.283185307179586;
  for (std::size_t i = 0; i < traits::size(cloud); ++i) {
    const auto p = traits::point(cloud, i);
    const double x = static_cast<double>(p.x()), y = static_cast<double>(p.y());
    if (!(x * x + y * y >= min_range_sq) || !std::isfinite(x * x + y * y)) continue;
    const double a = std::atan2(y, x) + 3.141592653589793;  // [0, 2 pi]
    filled[std::min(sectors - 1, static_cast<std::size_t>(a * per_radian))] = 1;
  }
  const auto count = static_cast<double>(std::count(filled.begin(), filled.end(), 1));
  return count / static_cast<double>(sectors);
}

/// How long frames at these timestamps last: their span and one frame period
/// (odometry::frame_period, the median gap; 0 for fewer than two).
inline double recorded_duration(const std::vector<double>& times) {
  if (times.size() < 2) return 0.0;
  return times.back() - times.front() + odometry::frame_period(times);
}

/// The median coverage of the first, middle and last frame of `frames` (0 with none).
template <class Frames>
double median_azimuth_coverage(const Frames& frames, const OdometryChoiceOptions& options) {
  const std::size_t n = frames.size();
  if (n == 0) return 0.0;
  double c[3] = {azimuth_coverage(frames[0], options), azimuth_coverage(frames[n / 2], options),
                 azimuth_coverage(frames[n - 1], options)};
  std::sort(c, c + 3);
  return c[1];
}

/// StageTuning::hots_odometry resolved for the base's frames and timestamps from frame_index
/// (see the conventions); base and joint are kept as asked.
template <class Frames>
OdometryChoice choose_odometry(HotsOdometry asked, const Frames& base_frames,
                               const std::vector<double>& base_times,
                               const OdometryChoiceOptions& options) {
  if (asked != HotsOdometry::automatic)
    return {asked, std::string("asked for the ") + to_string(asked) + " odometry"};
  char text[160];
  const double duration = recorded_duration(base_times);
  if (!(duration >= options.min_duration_s)) {
    std::snprintf(text, sizeof text,
                  "joint: the drive lasts %.1f s, under the %.0f s where the base's own odometry "
                  "serves as well",
                  duration, options.min_duration_s);
    return {HotsOdometry::joint, text};
  }
  const double coverage = median_azimuth_coverage(base_frames, options);
  if (!(coverage >= options.min_azimuth_coverage)) {
    std::snprintf(text, sizeof text,
                  "joint: the base sees %.0f %% of the azimuth around it (all around: %.0f %%), "
                  "so the target's scans steady the poses",
                  100.0 * coverage, 100.0 * options.min_azimuth_coverage);
    return {HotsOdometry::joint, text};
  }
  std::snprintf(text, sizeof text,
                "base: the drive lasts %.1f s and the base sees %.0f %% of the azimuth around "
                "it; its own odometry is run once for every hypothesis and target",
                duration, 100.0 * coverage);
  return {HotsOdometry::base, text, true};
}

}  // namespace ulc
