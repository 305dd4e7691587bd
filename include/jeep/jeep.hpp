// JEEP: joint estimation of the extrinsic and the poses over the first K frame pairs (the
// paper's section "Joint Estimation of Extrinsic and Pose").
//
// Conventions this header owns (frames and poses: odometry.hpp):
//   - Input: the frames of base LiDAR a and target LiDAR b (any random-access container of
//     traits clouds, per-point times relative to each frame's timestamp), their timestamps
//     (seconds, own clocks; t_base = t_target + odometry.time_offset_s) and an initial
//     C = T_base_target (TERRA's rotation with zero translation, or a user's guess).
//   - Frames are paired by timestamp (frame_pairing.hpp); the first K pairs are used.
//   - Motion bootstrap: odometry of a alone over the K frames gives the twists that deskew the
//     first round's scans (C does not enter it).
//   - A round: the pose phase (odometry.hpp: both scans of each pair against their own maps,
//     b through C, eq:je_odom) from scans deskewed with the previous round's twists, then the
//     calibration phase (map_registration.hpp: map b, made from b's scans and poses, registered
//     to map a from C, eq:calib_map) gives the next C. Each round starts its maps afresh; the
//     previous round's poses are the pose phase's initial guesses. The first round's
//     calibration phase searches a few starts around C (start_search.hpp).
//   - Settled: the round changed C by less than settle_translation / settle_rotation and every
//     pose of a by less than the same. No settling within max_rounds (the paper: "exceeding a
//     certain number of iterations is a failure"; 10) gives status not_converged.
//   - Acceptance (status rejected otherwise), see acceptance.hpp.
//   - Nothing here throws or prints; the result is the same for any number of threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "jeep/acceptance.hpp"
#include "jeep/map_registration.hpp"
#include "jeep/options.hpp"
#include "jeep/start_search.hpp"
#include "jeep/status.hpp"
#include "jeep/two_way.hpp"
#include "odometry/frame_pairing.hpp"
#include "odometry/odometry.hpp"
#include "odometry/run_odometry.hpp"
#include "odometry/scan_preparation.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace jeep {

using ulc::Vec6d;

/// What one round did.
struct JeepRound {
  Isometry3d extrinsic = Isometry3d::Identity();  ///< C after the round
  double change_translation = 0.0;                ///< m, C before -> after
  double change_rotation = 0.0;                   ///< rad
  double pose_change_translation = 0.0;           ///< m, largest over the poses of a
  double pose_change_rotation = 0.0;              ///< rad
  ulc::RegistrationStatus calibration_status = ulc::RegistrationStatus::ok;
  std::size_t failed_steps = 0;
};

struct JeepResult {
  JeepStatus status = JeepStatus::ok;
  const char* reason = "";
  Isometry3d extrinsic = Isometry3d::Identity();  ///< C = T_base_target
  std::vector<odometry::FramePair> pairs;         ///< the pairs used (indices into the inputs)
  std::vector<Isometry3d> poses_a;                ///< per pair: P_a = T_mapa_a at a's timestamp
  std::vector<Isometry3d> poses_b;                ///< per pair: P_b = T_mapb_b at b's timestamp
  std::vector<Vec6d> twists;  ///< per pair: a's body twist over its sweep, per second
  int rounds = 0;
  RegistrationResult<double> calibration;  ///< the last calibration phase
  StartSearchReport start_search;          ///< the first calibration phase's start search
  AcceptanceReport acceptance;             ///< accepted: by acceptance.hpp's rule
  TwoWayResult two_way;  ///< the last step when JeepOptions::two_way (applied: it was used)
  std::vector<JeepRound> trace;
  /// The last round's maps (eq:build_map) at calibration.target_voxel, in the frames of
  /// poses_a and poses_b: where they overlap, map_a = C * map_b.
  std::vector<ulc::Vec3d> map_a, map_b;

  bool ok() const { return status == JeepStatus::ok; }
};

namespace detail {

inline void pose_change(const Isometry3d& before, const Isometry3d& after, double& translation,
                        double& rotation) {
  const Isometry3d d = before.inverse() * after;
  translation = std::max(translation, d.translation().norm());
  rotation = std::max(rotation, ulc::so3_log(d.linear()).norm());
}

}  // namespace detail

template <class FramesA, class FramesB>
JeepResult run_jeep(const FramesA& frames_a, const std::vector<double>& times_a,
                    const FramesB& frames_b, const std::vector<double>& times_b,
                    const Isometry3d& initial, const JeepOptions& options = {},
                    const odometry::ProgressFn& progress = {}) {
  using S = ulc::traits::scalar_t<odometry::detail::frame_cloud_t<FramesA>>;
  JeepResult result;
  result.extrinsic = initial;
  auto fail = [&](JeepStatus s, const char* why) {
    result.status = s;
    result.reason = why;
    return result;
  };
  if (options.frames < 1 || options.max_rounds < 1 ||
      !odometry::valid_odometry_options(options.odometry) || options.calibration.stages.empty() ||
      options.refine_stages < 1 || !(options.default_period > 0.0))
    return fail(JeepStatus::invalid_input, "bad options");
  if (frames_a.size() != times_a.size() || frames_b.size() != times_b.size())
    return fail(JeepStatus::invalid_input, "frame and timestamp counts differ");
  if (!odometry::timestamps_usable(times_a) || !odometry::timestamps_usable(times_b))
    return fail(JeepStatus::invalid_input, "timestamps not finite and nondecreasing");
  if (!initial.matrix().allFinite())
    return fail(JeepStatus::invalid_input, "initial extrinsic not finite");

  const odometry::OdometryOptions& odo = options.odometry;
  double period_a = odometry::frame_period(times_a), period_b = odometry::frame_period(times_b);
  if (!(period_a > 0.0)) period_a = options.default_period;
  if (!(period_b > 0.0)) period_b = period_a;
  std::vector<odometry::FramePair> pairs =
      odometry::pair_frames(times_a, times_b, odo.time_offset_s, odo.max_pair_gap * period_a);
  if (pairs.empty()) return fail(JeepStatus::too_few_frames, "no frame of b near a frame of a");
  if (pairs.size() > options.frames) pairs.resize(options.frames);
  result.pairs = pairs;
  const std::size_t K = pairs.size();
  std::vector<double> t_a(K), t_b(K);
  for (std::size_t k = 0; k < K; ++k) {
    t_a[k] = times_a[pairs[k].a];
    t_b[k] = times_b[pairs[k].b] + odo.time_offset_s;
  }

  // Motion bootstrap: a alone, undeskewed, then once more deskewed with what it found.
  std::vector<Vec6d> twists(K, Vec6d::Zero());
  // One pass suffices: mid-sweep poses are unbiased by the missing deskew (odometry.hpp).
  for (int pass = 0; pass < 1 && K >= 2; ++pass) {
    odometry::Odometry<S> single(odo);
    std::vector<Isometry3d> mids;
    std::vector<double> mid_times;
    for (std::size_t k = 0; k < K; ++k) {
      if (pass > 0) single.set_twist(twists[k]);
      const auto scan =
          odometry::prepare_scan<S>(frames_a[pairs[k].a], twists[k], period_a, odo.scan);
      const odometry::OdometryStep step = single.step(scan, t_a[k], nullptr, t_a[k]);
      mids.push_back(step.mid_pose_a);
      mid_times.push_back(step.mid_time);
    }
    twists = odometry::twists_from_mid_poses(mids, mid_times);
  }

  Isometry3d C = initial;
  std::vector<Isometry3d> previous_poses;
  bool settled = false;
  for (int round = 1; round <= options.max_rounds && !settled; ++round) {
    // Pose phase (eq:je_odom). After the first round the previous poses are close guesses:
    // the fine registration stage alone, and the calibration phase's fine stages alone.
    odometry::OdometryOptions round_odo = odo;
    round_odo.single_stage = odo.single_stage || round > 1;
    odometry::Odometry<S> pose_phase(round_odo, C);
    std::vector<odometry::PreparedScan<S>> scans_a(K), scans_b(K);
    std::vector<Isometry3d> mids(K), poses_a(K), poses_b(K), scan_poses_a(K), scan_poses_b(K);
    std::vector<double> mid_times(K);
    JeepRound trace;
    for (std::size_t k = 0; k < K; ++k) {
      scans_a[k] = odometry::prepare_scan<S>(frames_a[pairs[k].a], twists[k], period_a, odo.scan);
      scans_b[k] = odometry::prepare_scan<S>(
          frames_b[pairs[k].b], pose_phase.target_twist(twists[k]), period_b, odo.scan);
      pose_phase.set_twist(twists[k]);
      std::optional<Isometry3d> guess;
      if (!previous_poses.empty()) guess = previous_poses[k];
      const odometry::OdometryStep step =
          pose_phase.step(scans_a[k], t_a[k], &scans_b[k], t_b[k], guess);
      if (k > 0 && !step.registered) ++trace.failed_steps;
      mids[k] = step.mid_pose_a;
      mid_times[k] = step.mid_time;
      scan_poses_a[k] = step.scan_pose_a;
      scan_poses_b[k] = step.scan_pose_b;
    }
    // Mid-sweep poses are unbiased by the deskew twists' errors; their central differences
    // give the next round's twists, and the poses at the timestamps.
    twists = odometry::twists_from_mid_poses(mids, mid_times, twists[0]);
    for (std::size_t k = 0; k < K; ++k) {
      poses_a[k] = mids[k] * ulc::se3_exp(Vec6d((t_a[k] - mid_times[k]) * twists[k]));
      poses_b[k] = pose_phase.target_pose(poses_a[k], t_a[k], t_b[k], twists[k]);
    }

    // Calibration phase (eq:calib_map): map b onto map a.
    std::vector<const std::vector<ulc::Vec3<S>>*> dense_a(K), dense_b(K);
    for (std::size_t k = 0; k < K; ++k) {
      dense_a[k] = &scans_a[k].dense;
      dense_b[k] = &scans_b[k].dense;
    }
    const auto map_a = assemble_map<S>(dense_a, scan_poses_a);
    const auto map_b = assemble_map<S>(dense_b, scan_poses_b);
    const auto target = map_target(map_a, options.calibration);
    MapRegistrationOptions stages = options.calibration;
    if (round > 1 && stages.stages.size() > options.refine_stages)
      stages.stages.erase(stages.stages.begin(),
                          stages.stages.end() - static_cast<std::ptrdiff_t>(options.refine_stages));
    const auto calibration =
        round == 1 ? register_maps_searching(map_b, target, C, stages, options.start_search,
                                             &result.start_search)
                   : register_maps(map_b, target, C, stages);
    trace.calibration_status = calibration.status;

    detail::pose_change(C, calibration.pose, trace.change_translation, trace.change_rotation);
    for (std::size_t k = 0; k < K && !previous_poses.empty(); ++k)
      detail::pose_change(previous_poses[k], poses_a[k], trace.pose_change_translation,
                          trace.pose_change_rotation);
    const bool usable = calibration.status != ulc::RegistrationStatus::too_few_correspondences &&
                        calibration.status != ulc::RegistrationStatus::invalid_input;
    if (usable) C = calibration.pose;
    trace.extrinsic = C;
    result.trace.push_back(trace);
    result.rounds = round;
    result.extrinsic = C;
    // Outputs in a's frame at its first timestamp (internally: at its first mid-sweep).
    const Isometry3d to_first = poses_a[0].inverse();
    const Isometry3d to_first_b = C.inverse() * to_first * C;
    result.poses_a.resize(K);
    result.poses_b.resize(K);
    for (std::size_t k = 0; k < K; ++k) {
      result.poses_a[k] = to_first * poses_a[k];
      result.poses_b[k] =
          to_first_b * pose_phase.target_pose(poses_a[k], t_a[k], t_b[k], twists[k]);
    }
    result.twists = twists;
    result.calibration = calibration;
    if (progress)
      progress(static_cast<std::size_t>(round), static_cast<std::size_t>(options.max_rounds));
    if (!usable) return fail(JeepStatus::registration_failed, calibration.reason);
    settled = !previous_poses.empty() && trace.change_translation < options.settle_translation &&
              trace.change_rotation < options.settle_rotation &&
              trace.pose_change_translation < options.settle_translation &&
              trace.pose_change_rotation < options.settle_rotation;
    if (K == 1)  // no poses to settle: C alone decides
      settled = trace.change_translation < options.settle_translation &&
                trace.change_rotation < options.settle_rotation;
    previous_poses = poses_a;
    if (settled && options.two_way) {
      result.two_way = two_way_extrinsic(map_a, map_b, C, stages);
      C = result.two_way.extrinsic;
      result.extrinsic = C;
    }
    if (settled || round == options.max_rounds) {
      result.acceptance = assess(map_a, map_b, target, options.calibration, C, options.acceptance);
      // In the output poses' frames (see to_first below).
      const Isometry3d to_first = poses_a[0].inverse();
      const Isometry3d to_first_b = C.inverse() * to_first * C;
      for (const auto& p : downsampled(map_a, options.calibration.target_voxel).points)
        result.map_a.push_back(to_first * p.template cast<double>());
      for (const auto& p : downsampled(map_b, options.calibration.target_voxel).points)
        result.map_b.push_back(to_first_b * p.template cast<double>());
    }
  }
  if (!settled)
    return fail(JeepStatus::not_converged,
                "the extrinsic and the poses did not settle within max_rounds rounds");
  if (result.trace.back().failed_steps > 0)
    return fail(JeepStatus::registration_failed,
                "a pose-phase step had too few correspondences in the last round");
  if (!result.acceptance.accepted) return fail(JeepStatus::rejected, result.acceptance.reason);
  return result;
}

}  // namespace jeep
