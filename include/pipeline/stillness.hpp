// Did the rig stand still for the whole recording? A parked rig recorded for seconds has many
// frames but no motion: HOTS's odometry and time synchronisation have nothing to work with (a
// parked 32-mid40, 10 s: HOTS's clock offset untrusted, the call failed; with the clocks given
// HOTS moved JEEP's 1.1 cm answer to 2.0 cm), and the clock offset cannot move its extrinsic.
// Such a recording is calibrated as a static snapshot is (attempt.hpp): JEEP's answer, judged
// by the free-space check and the contest of TERRA's hypotheses, and HOTS skipped with the
// reason (docs/pipeline.md, "Hand-over between stages"; docs/BENCHMARKS.md, "A parked rig
// recorded for seconds").
//
// Conventions this header owns:
//   - Only the base's frames are looked at (the rig is rigid): StillnessOptions::samples frames
//     spread evenly over the sequence (the last among them) are each registered to the first
//     (point-to-plane, both thinned to `voxel`, from the identity, coarse_to_fine_stages).
//   - Still when every registration converged with a condition of at least min_condition and
//     an inlier ratio of at least min_inlier_ratio, and found the frame within max_travel_m and
//     max_turn_deg of the first. The first frame that fails ends the check: one that lies away
//     from the first ("the rig moved", decided), or one whose registration cannot tell
//     (degenerate, a large move, too few points; not decided). Either way the rig is not still
//     and HOTS runs as on any drive and judges it. A moving drive costs one registration.
//   - Nothing here throws or prints; the same for any number of threads (each registration is).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "pipeline/stillness_options.hpp"
#include "pipeline/text_format.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/registration_target.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace ulc {
namespace stillness_detail {

using calibrate_detail::cm;
using calibrate_detail::fixed;

/// The indices of the frames compared with frame 0: `samples` of them, spread evenly over
/// [1, count - 1], the last among them, each once.
inline std::vector<std::size_t> compared_frames(std::size_t count, std::size_t samples) {
  std::vector<std::size_t> out;
  if (count < 2 || samples == 0) return out;
  const std::size_t n = std::min(samples, count - 1);
  for (std::size_t j = 1; j <= n; ++j) out.push_back(j * (count - 1) / n);
  return out;
}

/// One compared frame's registration to the first, as the check reads it.
struct FrameMove {
  bool registered = false;  ///< converged, not degenerate
  double travel_m = 0.0, turn_deg = 0.0, condition = 0.0, inlier_ratio = 0.0;
};

template <class Cloud, class Target>
FrameMove move_from_first(const Cloud& frame, const Target& first, double voxel) {
  const auto thin = voxel_downsample(frame, voxel);
  FrameMove m;
  if (!thin.ok()) return m;
  const auto r = register_point_to_plane(thin.cloud, first, Isometry3d::Identity(),
                                         coarse_to_fine_stages(1.0));
  m.registered = r.ok();
  m.travel_m = r.pose.translation().norm();
  m.turn_deg = Eigen::AngleAxisd(r.pose.linear()).angle() * kDegPerRad;
  m.condition = r.condition;
  m.inlier_ratio = r.inlier_ratio();
  return m;
}

inline void add_move(StillnessReport& report, const FrameMove& m) {
  const bool first = report.frames_compared == 0;
  report.max_travel_m = std::max(report.max_travel_m, m.travel_m);
  report.max_turn_deg = std::max(report.max_turn_deg, m.turn_deg);
  report.min_condition = first ? m.condition : std::min(report.min_condition, m.condition);
  report.min_inlier_ratio =
      first ? m.inlier_ratio : std::min(report.min_inlier_ratio, m.inlier_ratio);
  ++report.frames_compared;
}

/// A registration that can tell where the frame was taken: converged, every direction pinned,
/// most points on the first frame's surfaces.
inline bool tells(const FrameMove& m, const StillnessOptions& o) {
  return m.registered && m.condition >= o.min_condition && m.inlier_ratio >= o.min_inlier_ratio;
}

inline bool in_place(const FrameMove& m, const StillnessOptions& o) {
  return m.travel_m <= o.max_travel_m && m.turn_deg <= o.max_turn_deg;
}

/// "base frame 12, 1.2 s after the first,"
inline std::string frame_words(std::size_t k, double after_s) {
  return "base frame " + std::to_string(k) + ", " + fixed(after_s, 1) + " s after the first,";
}

/// The verdict when frame k (after_s after the first) ends the check: it cannot tell, or it
/// lies away from the first.
inline void not_still(StillnessReport& report, const FrameMove& m, std::size_t k, double after_s,
                      const StillnessOptions& o) {
  report.span_s = after_s;
  report.decided = tells(m, o);
  report.reason = report.decided
                      ? "the rig moved: " + frame_words(k, after_s) + " lies " + cm(m.travel_m) +
                            " and " + fixed(m.turn_deg, 2) + " deg from where the first was taken"
                      : "not judged still: " + frame_words(k, after_s) +
                            " does not register to the first in place (the rig "
                            "moved, or the scene cannot show it)";
}

}  // namespace stillness_detail

/// Whether the rig stood still over the base's `frames` (timestamps `times`); see the top.
template <class Frames>
StillnessReport judge_stillness(const Frames& frames, const std::vector<double>& times,
                                const StillnessOptions& o) {
  using namespace stillness_detail;
  StillnessReport report;
  const std::vector<std::size_t> compared =
      compared_frames(std::min(frames.size(), times.size()), o.samples);
  if (compared.empty()) return report;
  const auto first_thin = voxel_downsample(frames[0], o.voxel);
  if (!first_thin.ok()) {
    report.reason =
        std::string("the base's first frame could not be thinned: ") + first_thin.reason;
    return report;
  }
  const PlaneCloud<double> first(first_thin.cloud);
  for (std::size_t k : compared) {
    const FrameMove m = move_from_first(frames[k], first, o.voxel);
    add_move(report, m);
    if (!tells(m, o) || !in_place(m, o)) {
      not_still(report, m, k, times[k] - times[0], o);
      return report;
    }
  }
  report.still = report.decided = true;
  report.span_s = times[compared.back()] - times[0];
  report.reason = "the rig stood still: the base moved at most " + cm(report.max_travel_m) +
                  " and " + fixed(report.max_turn_deg, 2) + " deg over " + fixed(report.span_s, 1) +
                  " s (" + std::to_string(report.frames_compared) +
                  " base frames registered to the first)";
  return report;
}

}  // namespace ulc
