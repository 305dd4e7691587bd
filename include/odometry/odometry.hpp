// Odometry: the pose phase of JEEP (the paper's eq:je_odom) run frame pair after frame pair,
// and its single-LiDAR special case.
//
// Conventions this header owns:
//   - C = T_base_target (p_a = C p_b). Map a lives in base LiDAR a's coordinates at the first
//     paired a frame; map b in target LiDAR b's coordinates at that same instant, so that
//     p_mapa = C p_mapb and registering map b to map a yields C directly (calibration phase).
//   - Poses: P_a(t) = T_mapa_a(t), P_b(t) = T_mapb_b(t) = C^-1 P_a(t) C (rigid mount).
//   - Motion model: a constant body-frame twist xi of LiDAR a (per second, [rho; phi]):
//     P_a(t + s) = P_a(t) exp(s xi). It predicts the next pose, deskews scans (b's twist is
//     Ad(C^-1) xi) and carries a's pose to b's timestamp: P_a(t_b) = P_a(t_a) exp((t_b - t_a) xi).
//   - One step estimates P_a(t_a) from both scans against their own maps (maps built from the
//     previous frames), the target scan entering through the current extrinsic:
//       min_T  sum_a rho(n . (T x - p)) + w_b sum_b rho(n . (C^-1 T M C x - p)),
//     M = exp((t_b - t_a) xi), T <- exp(d) T: the joint Jacobian of the paper (point_to_plane.hpp
//     terms with pre = M C, post = C^-1). Registration runs in two stages (coarse gate and soft
//     kernel, then half the gate and a tight kernel). The first frame defines the maps.
//   - After a step, the twist is re-estimated from the last two poses, and the dense scans are
//     added to the maps at their poses. A step whose registration had too few correspondences
//     keeps the predicted pose and adds nothing to the maps.
//   - Frames are paired by timestamp (frame_pairing.hpp): one step per pair; unpaired frames
//     get a pose extrapolated with the twist of the nearest pair in time (estimated = false).
#pragma once

#include <cmath>
#include <cstddef>
#include <functional>
#include <optional>
#include <type_traits>
#include <vector>

#include "odometry/frame_pairing.hpp"
#include "odometry/local_map.hpp"
#include "odometry/options.hpp"
#include "odometry/scan_preparation.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/registration_types.hpp"
#include "ulc/core/types.hpp"

namespace odometry {

using ulc::RegistrationOptions;
using ulc::RegistrationStatus;
using ulc::Vec6d;

inline bool valid_odometry_options(const OdometryOptions& o) {
  return valid_scan_options(o.scan) && valid_local_map_options(o.map) && o.gate > 0.0 &&
         o.initial_gate > 0.0 && o.coarse_kernel > 0.0 && o.fine_kernel > 0.0 &&
         o.max_iterations >= 1 && o.target_weight >= 0.0 && std::isfinite(o.time_offset_s) &&
         o.max_pair_gap > 0.0 && o.min_condition >= 0.0 && o.min_condition < 1.0 &&
         o.translation_tolerance >= 0.0 && o.rotation_tolerance >= 0.0;
}

/// The two registration stages of one step, first-stage gate `gate`.
inline std::vector<RegistrationOptions> odometry_stages(const OdometryOptions& o, double gate) {
  RegistrationOptions coarse;
  coarse.max_iterations = o.max_iterations;
  coarse.max_correspondence_distance = gate;
  coarse.kernel = ulc::RobustKernel::geman_mcclure(o.coarse_kernel);
  coarse.translation_tolerance = 1e-3;
  coarse.rotation_tolerance = 1e-4;
  coarse.min_correspondences = o.min_correspondences;
  coarse.min_condition = o.min_condition;
  RegistrationOptions fine = coarse;
  fine.max_correspondence_distance = gate / 2;
  fine.kernel = ulc::RobustKernel::geman_mcclure(o.fine_kernel);
  fine.translation_tolerance = o.translation_tolerance;
  fine.rotation_tolerance = o.rotation_tolerance;
  return {coarse, fine};
}

/// What one step did.
struct OdometryStep {
  RegistrationStatus status = RegistrationStatus::ok;
  const char* reason = "";
  bool registered = false;  ///< false for the first frame and for steps that kept the guess
  double t_a = 0.0;         ///< a's timestamp
  double t_b = 0.0;         ///< b's timestamp in a's clock
  Isometry3d pose_a = Isometry3d::Identity();  ///< P_a(t_a) = T_mapa_a
  Isometry3d pose_b = Isometry3d::Identity();  ///< P_b(t_b) = T_mapb_b (multi-LiDAR only)
  /// P_a at the middle of a's sweep (mid_time): unbiased by an error of the deskew twist.
  Isometry3d mid_pose_a = Isometry3d::Identity();
  double mid_time = 0.0;
  /// The poses the prepared (deskewed) scans were registered and mapped with. They differ from
  /// pose_a, pose_b by the deskew twist's error over half a sweep (see step()).
  Isometry3d scan_pose_a = Isometry3d::Identity();
  Isometry3d scan_pose_b = Isometry3d::Identity();
  Vec6d twist = Vec6d::Zero();  ///< a's body twist after the step, per second
  int iterations = 0;           ///< correspondence searches
  int solver_iterations = 0;    ///< Gauss-Newton steps
  std::size_t source_points = 0;
  std::size_t correspondences = 0;
  std::size_t inliers = 0;
  double condition = 0.0;
};

/// a's body twist over each frame's sweep from the poses at mid-sweep: central differences,
/// one-sided at the ends; a single frame keeps `fallback`.
inline std::vector<Vec6d> twists_from_mid_poses(const std::vector<Isometry3d>& mids,
                                                const std::vector<double>& mid_times,
                                                const Vec6d& fallback = Vec6d::Zero()) {
  const std::size_t n = mids.size();
  std::vector<Vec6d> out(n, fallback);
  if (n < 2) return out;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t lo = k == 0 ? 0 : k - 1;
    const std::size_t hi = k + 1 == n ? n - 1 : k + 1;
    const double dt = mid_times[hi] - mid_times[lo];
    if (dt > 0.0) out[k] = ulc::se3_log(Isometry3d(mids[lo].inverse() * mids[hi])) / dt;
  }
  return out;
}

/// Incremental odometry over prepared scans (scan_preparation.hpp), single or multi-LiDAR.
template <typename S>
class Odometry {
 public:
  /// Multi-LiDAR with extrinsic C = T_base_target; without one, a alone.
  explicit Odometry(const OdometryOptions& options,
                    const std::optional<Isometry3d>& extrinsic = std::nullopt)
      : options_(options), map_a_(options.map), map_b_(options.map) {
    if (extrinsic) {
      C_ = *extrinsic;
      C_inv_ = extrinsic->inverse();
      multi_ = true;
    }
  }

  bool multi() const { return multi_; }
  const Isometry3d& extrinsic() const { return C_; }
  std::size_t frames() const { return frames_; }
  const LocalMap<S>& map_a() const { return map_a_; }
  const LocalMap<S>& map_b() const { return map_b_; }

  /// a's body twist (per second): zero until two frames were registered, unless set.
  const Vec6d& twist() const { return twist_; }
  bool has_velocity() const { return has_velocity_; }
  /// Sets the twist (a hint, e.g. from an earlier pass): deskews the next scans and predicts.
  void set_twist(const Vec6d& xi) {
    twist_ = xi;
    has_velocity_ = true;
  }
  /// b's body twist for a's twist xi: Ad(C^-1) xi.
  Vec6d target_twist(const Vec6d& xi) const { return ulc::adjoint(C_inv_) * xi; }
  /// P_b(t_b) for a pose of a at t_a and a's twist.
  Isometry3d target_pose(const Isometry3d& pose_a, double t_a, double t_b, const Vec6d& xi) const {
    return C_inv_ * pose_a * ulc::se3_exp(Vec6d((t_b - t_a) * xi)) * C_;
  }

  /// One frame (pair). `b` is ignored in single-LiDAR mode; t_b is b's timestamp in a's clock.
  /// `guess`, when given, replaces the constant-velocity prediction of P_a(t_a).
  OdometryStep step(const PreparedScan<S>& a, double t_a, const PreparedScan<S>* b, double t_b,
                    const std::optional<Isometry3d>& guess = std::nullopt) {
    OdometryStep out;
    out.t_a = t_a;
    out.t_b = t_b;
    const bool with_b = multi_ && b != nullptr;
    // Mid-sweep bookkeeping: a scan deskewed with a wrong twist is sheared about its middle,
    // so its registered pose is only unbiased at mid-sweep. Velocities come from mid-sweep
    // poses; estimating them from frame-start poses feeds deskew errors back with gain -1
    // (a period-2 oscillation of the speed estimate that never decays).
    const double half = 0.5 * a.duration;
    const Isometry3d to_mid = ulc::se3_exp(Vec6d(half * a.twist));
    const Isometry3d M = ulc::se3_exp(Vec6d((t_b - t_a) * twist_));  // a's motion t_a -> t_b
    // Pose of the prepared scan. The first frame's mid-sweep pose is the maps' origin.
    Isometry3d T = to_mid.inverse();
    if (frames_ > 0) {
      const Isometry3d predicted =
          guess ? *guess
                : last_mid_pose_ * ulc::se3_exp(Vec6d((t_a + half - last_mid_t_) * twist_)) *
                      to_mid.inverse();
      using Term = ulc::PointToPlaneTerm<S, LocalMap<S>>;
      std::vector<Term> terms;
      terms.push_back(Term{a.sparse.data(), a.sparse.size(), &map_a_, Isometry3d::Identity(),
                           Isometry3d::Identity(), 1.0});
      if (with_b && options_.target_weight > 0.0 && !map_b_.empty())
        terms.push_back(Term{b->sparse.data(), b->sparse.size(), &map_b_, M * C_, C_inv_,
                             options_.target_weight});
      auto stages =
          odometry_stages(options_, has_velocity_ ? options_.gate : options_.initial_gate);
      if (has_velocity_ && options_.single_stage) stages.erase(stages.begin());
      const auto r = ulc::register_point_to_plane_terms(terms, predicted, stages);
      out.status = r.status;
      out.reason = r.reason;
      out.iterations = r.iterations;
      out.solver_iterations = r.solver_iterations;
      out.source_points = r.source_points;
      out.correspondences = r.correspondences;
      out.inliers = r.inliers;
      out.condition = r.condition;
      out.registered = r.status != RegistrationStatus::too_few_correspondences &&
                       r.status != RegistrationStatus::invalid_input;
      T = out.registered ? r.pose : predicted;
    }
    const Isometry3d mid = T * to_mid;
    if (out.registered) {
      const double dt = t_a + half - last_mid_t_;
      if (dt > 0.0) {
        twist_ = ulc::se3_log(Isometry3d(last_mid_pose_.inverse() * mid)) / dt;
        has_velocity_ = true;
      }
    }
    out.twist = twist_;
    out.scan_pose_a = T;
    out.scan_pose_b = C_inv_ * T * M * C_;
    out.mid_pose_a = mid;
    out.mid_time = t_a + half;
    out.pose_a = mid * ulc::se3_exp(Vec6d(-half * twist_));
    out.pose_b = multi_ ? target_pose(out.pose_a, t_a, t_b, twist_) : Isometry3d::Identity();
    // A step that kept its guess adds nothing: a wrong pose would spoil the maps for good.
    if (frames_ == 0 || out.registered) {
      map_a_.insert(transformed(a.dense, out.scan_pose_a), T.translation());
      if (with_b)
        map_b_.insert(transformed(b->dense, out.scan_pose_b), out.scan_pose_b.translation());
    }
    last_mid_pose_ = mid;
    last_mid_t_ = t_a + half;
    ++frames_;
    return out;
  }

  static std::vector<Vec3<S>> transformed(const std::vector<Vec3<S>>& points, const Isometry3d& T) {
    std::vector<Vec3<S>> out;
    out.reserve(points.size());
    for (const auto& p : points) out.push_back((T * p.template cast<double>()).template cast<S>());
    return out;
  }

 private:
  OdometryOptions options_;
  bool multi_ = false;
  Isometry3d C_ = Isometry3d::Identity();
  Isometry3d C_inv_ = Isometry3d::Identity();
  LocalMap<S> map_a_, map_b_;
  std::size_t frames_ = 0;
  Isometry3d last_mid_pose_ = Isometry3d::Identity();  ///< P_a at the last scan's mid-sweep
  double last_mid_t_ = 0.0;
  Vec6d twist_ = Vec6d::Zero();
  bool has_velocity_ = false;
};

}  // namespace odometry
