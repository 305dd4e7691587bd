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
//   - covariance_6x6: of the final C ([rho; phi], left: C <- exp(xi) C, base frame, m and rad)
//     from the last round's calibration problem at that C: map b at the last stage's source
//     voxel against map a's planes, the delete-one-cluster jackknife with the points in one
//     covariance_cell-sized cell of map a as a cluster (ulc/core/registration_covariance.hpp:
//     the robust kernel's curvature as the bread), plus delta delta^T with delta the two-way
//     step's move from the forward registration's answer (two models of the same maps; one
//     sample of an error all cells share). Empty when it cannot be formed (a singular problem).
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
#include "ulc/core/registration_covariance.hpp"
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
  std::optional<ulc::Mat6d> covariance_6x6;  ///< of extrinsic (see the header comment)
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

/// Why run_jeep cannot run; nullptr when it can.
template <class FramesA, class FramesB>
const char* input_problem(const FramesA& frames_a, const std::vector<double>& times_a,
                          const FramesB& frames_b, const std::vector<double>& times_b,
                          const Isometry3d& initial, const JeepOptions& options) {
  if (options.frames < 1 || options.max_rounds < 1 ||
      !odometry::valid_odometry_options(options.odometry) || options.calibration.stages.empty() ||
      options.refine_stages < 1 || !(options.default_period > 0.0) ||
      !(options.covariance_cell >= 0.0))
    return "bad options";
  if (frames_a.size() != times_a.size() || frames_b.size() != times_b.size())
    return "frame and timestamp counts differ";
  if (!odometry::timestamps_usable(times_a) || !odometry::timestamps_usable(times_b))
    return "timestamps not finite and nondecreasing";
  if (!initial.matrix().allFinite()) return "initial extrinsic not finite";
  return nullptr;
}

/// The first K frame pairs, their timestamps (b's on a's clock) and the frame periods.
struct JeepPairs {
  std::vector<odometry::FramePair> pairs;
  std::vector<double> t_a, t_b;
  double period_a = 0.0, period_b = 0.0;
  std::size_t size() const { return pairs.size(); }
};

inline JeepPairs jeep_pairs(const std::vector<double>& times_a, const std::vector<double>& times_b,
                            const JeepOptions& options) {
  const odometry::OdometryOptions& odo = options.odometry;
  JeepPairs p;
  p.period_a = odometry::frame_period(times_a);
  p.period_b = odometry::frame_period(times_b);
  if (!(p.period_a > 0.0)) p.period_a = options.default_period;
  if (!(p.period_b > 0.0)) p.period_b = p.period_a;
  p.pairs =
      odometry::pair_frames(times_a, times_b, odo.time_offset_s, odo.max_pair_gap * p.period_a);
  if (p.pairs.size() > options.frames) p.pairs.resize(options.frames);
  for (const odometry::FramePair& pair : p.pairs) {
    p.t_a.push_back(times_a[pair.a]);
    p.t_b.push_back(times_b[pair.b] + odo.time_offset_s);
  }
  return p;
}

/// Motion bootstrap: a alone, undeskewed; its mid-sweep poses are unbiased by the missing
/// deskew (odometry.hpp), so one pass gives the twists that deskew the first round.
template <typename S, class FramesA>
std::vector<Vec6d> bootstrap_twists(const FramesA& frames_a, const JeepPairs& p,
                                    const odometry::OdometryOptions& odo) {
  const std::size_t K = p.size();
  std::vector<Vec6d> twists(K, Vec6d::Zero());
  if (K < 2) return twists;
  odometry::Odometry<S> single(odo);
  std::vector<Isometry3d> mids;
  std::vector<double> mid_times;
  for (std::size_t k = 0; k < K; ++k) {
    const auto scan =
        odometry::prepare_scan<S>(frames_a[p.pairs[k].a], twists[k], p.period_a, odo.scan);
    const odometry::OdometryStep step = single.step(scan, p.t_a[k], nullptr, p.t_a[k]);
    mids.push_back(step.mid_pose_a);
    mid_times.push_back(step.mid_time);
  }
  return odometry::twists_from_mid_poses(mids, mid_times);
}

/// One round's pose phase (eq:je_odom): both scans of each pair against their own maps, b
/// through C, deskewed with the previous round's twists; it updates the twists.
template <typename S>
struct PosePhase {
  odometry::Odometry<S> odometry;
  std::vector<odometry::PreparedScan<S>> scans_a, scans_b;
  std::vector<Isometry3d> poses_a;  ///< at a's timestamps
  std::vector<Isometry3d> scan_poses_a, scan_poses_b;
  std::size_t failed_steps = 0;
};

template <typename S, class FramesA, class FramesB>
PosePhase<S> pose_phase(const FramesA& frames_a, const FramesB& frames_b, const JeepPairs& p,
                        const Isometry3d& C, const std::vector<Isometry3d>& previous_poses,
                        int round, const odometry::OdometryOptions& odo,
                        std::vector<Vec6d>& twists) {
  // After the first round the previous poses are close guesses: the fine stage alone.
  odometry::OdometryOptions round_odo = odo;
  round_odo.single_stage = odo.single_stage || round > 1;
  const std::size_t K = p.size();
  PosePhase<S> phase{odometry::Odometry<S>(round_odo, C), {}, {}, {}, {}, {}, 0};
  std::vector<Isometry3d> mids(K);
  std::vector<double> mid_times(K);
  for (std::size_t k = 0; k < K; ++k) {
    phase.scans_a.push_back(
        odometry::prepare_scan<S>(frames_a[p.pairs[k].a], twists[k], p.period_a, odo.scan));
    phase.scans_b.push_back(odometry::prepare_scan<S>(
        frames_b[p.pairs[k].b], phase.odometry.target_twist(twists[k]), p.period_b, odo.scan));
    phase.odometry.set_twist(twists[k]);
    std::optional<Isometry3d> guess;
    if (!previous_poses.empty()) guess = previous_poses[k];
    const odometry::OdometryStep step =
        phase.odometry.step(phase.scans_a[k], p.t_a[k], &phase.scans_b[k], p.t_b[k], guess);
    if (k > 0 && !step.registered) ++phase.failed_steps;
    mids[k] = step.mid_pose_a;
    mid_times[k] = step.mid_time;
    phase.scan_poses_a.push_back(step.scan_pose_a);
    phase.scan_poses_b.push_back(step.scan_pose_b);
  }
  // Mid-sweep poses are unbiased by the deskew twists' errors; their central differences
  // give the next round's twists, and the poses at the timestamps.
  twists = odometry::twists_from_mid_poses(mids, mid_times, twists[0]);
  for (std::size_t k = 0; k < K; ++k)
    phase.poses_a.push_back(mids[k] * ulc::se3_exp(Vec6d((p.t_a[k] - mid_times[k]) * twists[k])));
  return phase;
}

/// One round's calibration phase (eq:calib_map): map b onto map a from C; the first round
/// searches a few starts around C (start_search.hpp), later ones run the fine stages alone.
template <typename S>
struct CalibrationPhase {
  std::vector<Vec3<S>> map_a, map_b;
  ulc::PlaneCloud<S> target;
  MapRegistrationOptions stages;
  RegistrationResult<double> registration;
};

template <typename S>
CalibrationPhase<S> calibration_phase(const PosePhase<S>& phase, const Isometry3d& C, int round,
                                      const JeepOptions& options, StartSearchReport* search) {
  const std::size_t K = phase.scans_a.size();
  std::vector<const std::vector<ulc::Vec3<S>>*> dense_a(K), dense_b(K);
  for (std::size_t k = 0; k < K; ++k) {
    dense_a[k] = &phase.scans_a[k].dense;
    dense_b[k] = &phase.scans_b[k].dense;
  }
  CalibrationPhase<S> out;
  out.map_a = assemble_map<S>(dense_a, phase.scan_poses_a);
  out.map_b = assemble_map<S>(dense_b, phase.scan_poses_b);
  out.target = map_target(out.map_a, options.calibration);
  out.stages = options.calibration;
  if (round > 1 && out.stages.stages.size() > options.refine_stages)
    out.stages.stages.erase(
        out.stages.stages.begin(),
        out.stages.stages.end() - static_cast<std::ptrdiff_t>(options.refine_stages));
  out.registration = round == 1 ? register_maps_searching(out.map_b, out.target, C, out.stages,
                                                          options.start_search, search)
                                : register_maps(out.map_b, out.target, C, out.stages);
  return out;
}

/// The round's poses and twists as outputs, in a's frame at its first timestamp (internally:
/// at its first mid-sweep).
template <typename S>
void output_poses(const PosePhase<S>& phase, const JeepPairs& p, const Isometry3d& C,
                  const std::vector<Vec6d>& twists, JeepResult& result) {
  const std::size_t K = p.size();
  const Isometry3d to_first = phase.poses_a[0].inverse();
  const Isometry3d to_first_b = C.inverse() * to_first * C;
  result.poses_a.resize(K);
  result.poses_b.resize(K);
  for (std::size_t k = 0; k < K; ++k) {
    result.poses_a[k] = to_first * phase.poses_a[k];
    result.poses_b[k] =
        to_first_b * phase.odometry.target_pose(phase.poses_a[k], p.t_a[k], p.t_b[k], twists[k]);
  }
  result.twists = twists;
}

/// Settled: C and every pose of a moved less than the settle thresholds this round (with one
/// pair there are no poses to settle: C alone decides).
inline bool settled(const JeepRound& trace, bool first_round, std::size_t K,
                    const JeepOptions& options) {
  const bool c_still = trace.change_translation < options.settle_translation &&
                       trace.change_rotation < options.settle_rotation;
  if (K == 1) return c_still;
  return !first_round && c_still && trace.pose_change_translation < options.settle_translation &&
         trace.pose_change_rotation < options.settle_rotation;
}

/// The last round's verdict: the acceptance rule (acceptance.hpp) on C, and the maps at
/// calibration.target_voxel in the output poses' frames.
template <typename S>
void judge_last_round(const PosePhase<S>& phase, const CalibrationPhase<S>& cal,
                      const Isometry3d& C, const JeepOptions& options, JeepResult& result) {
  result.acceptance =
      assess(cal.map_a, cal.map_b, cal.target, options.calibration, C, options.acceptance);
  const MapStage& last = cal.stages.stages.back();
  result.covariance_6x6 =
      ulc::point_to_plane_covariance(downsampled(cal.map_b, last.source_voxel).points, cal.target,
                                     C, last.registration, options.covariance_cell);
  if (result.covariance_6x6) {
    // The two-way step's move from the forward registration's answer: a sample of the
    // disagreement between two models of the same data (see the header comment).
    const Vec6d moved = ulc::se3_log(Isometry3d(cal.registration.pose * C.inverse()));
    *result.covariance_6x6 += moved * moved.transpose();
  }
  const Isometry3d to_first = phase.poses_a[0].inverse();
  const Isometry3d to_first_b = C.inverse() * to_first * C;
  for (const auto& p : downsampled(cal.map_a, options.calibration.target_voxel).points)
    result.map_a.push_back(to_first * p.template cast<double>());
  for (const auto& p : downsampled(cal.map_b, options.calibration.target_voxel).points)
    result.map_b.push_back(to_first_b * p.template cast<double>());
}

}  // namespace detail

/// See the header comment. progress(round, max_rounds) after each round.
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
  if (const char* why =
          detail::input_problem(frames_a, times_a, frames_b, times_b, initial, options))
    return fail(JeepStatus::invalid_input, why);
  const detail::JeepPairs p = detail::jeep_pairs(times_a, times_b, options);
  if (p.pairs.empty()) return fail(JeepStatus::too_few_frames, "no frame of b near a frame of a");
  result.pairs = p.pairs;
  std::vector<Vec6d> twists = detail::bootstrap_twists<S>(frames_a, p, options.odometry);

  Isometry3d C = initial;
  std::vector<Isometry3d> previous_poses;
  bool settled = false;
  for (int round = 1; round <= options.max_rounds && !settled; ++round) {
    const auto phase = detail::pose_phase<S>(frames_a, frames_b, p, C, previous_poses, round,
                                             options.odometry, twists);
    const auto cal = detail::calibration_phase(phase, C, round, options, &result.start_search);
    JeepRound trace;
    trace.failed_steps = phase.failed_steps;
    trace.calibration_status = cal.registration.status;
    detail::pose_change(C, cal.registration.pose, trace.change_translation, trace.change_rotation);
    for (std::size_t k = 0; k < p.size() && !previous_poses.empty(); ++k)
      detail::pose_change(previous_poses[k], phase.poses_a[k], trace.pose_change_translation,
                          trace.pose_change_rotation);
    const bool usable =
        cal.registration.status != ulc::RegistrationStatus::too_few_correspondences &&
        cal.registration.status != ulc::RegistrationStatus::invalid_input;
    if (usable) C = cal.registration.pose;
    trace.extrinsic = C;
    result.trace.push_back(trace);
    result.rounds = round;
    result.extrinsic = C;
    detail::output_poses(phase, p, C, twists, result);
    result.calibration = cal.registration;
    if (progress)
      progress(static_cast<std::size_t>(round), static_cast<std::size_t>(options.max_rounds));
    if (!usable) return fail(JeepStatus::registration_failed, cal.registration.reason);
    settled = detail::settled(trace, previous_poses.empty(), p.size(), options);
    previous_poses = phase.poses_a;
    if (settled && options.two_way) {
      result.two_way = two_way_extrinsic(cal.map_a, cal.map_b, C, cal.stages);
      C = result.extrinsic = result.two_way.extrinsic;
    }
    if (settled || round == options.max_rounds)
      detail::judge_last_round(phase, cal, C, options, result);
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
