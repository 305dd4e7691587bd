// The vocabulary of point-to-plane registration: what a target returns for a query, the
// options, the status and the result.
//
// Conventions this header owns:
//   - A registration estimates T_target_source (p_target = T * p_source), starting from an
//     initial guess, by Gauss-Newton with left perturbations T <- exp(dxi) T, xi = [rho; phi]
//     (lie.hpp).
//   - A target is any type with
//       bool find_plane(const Vec3d& query, double max_distance, PlaneMatch& out) const;
//     returning the plane (a point on it and its unit normal) of the nearest usable target
//     point within max_distance of the query, in the target frame. It must be safe to call
//     from several threads at once. PlaneCloud (registration_target.hpp) and jeep's local maps
//     are targets.
//   - Residual of a source point x: r = n . (T x - p). A correspondence is a source point whose
//     query found a plane within the gate (max_correspondence_distance); an inlier is a
//     correspondence with |r| <= inlier_distance.
//   - Distances in metres, angles in radians.
#pragma once

#include <cstddef>

#include "ulc/core/robust_kernel.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// A plane of the target: a point on it and its unit normal, in the target frame.
struct PlaneMatch {
  Vec3d point = Vec3d::Zero();
  Vec3d normal = Vec3d::Zero();
};

struct RegistrationOptions {
  /// Correspondence searches (outer iterations).
  int max_iterations = 30;
  /// Gauss-Newton steps per search, with the matches held fixed.
  int max_solver_iterations = 10;
  /// Gate: a source point further than this from every usable target point has no residual.
  double max_correspondence_distance = 1.0;
  /// Redescending, a few times a LiDAR's range noise: surfaces only one cloud saw stop pulling.
  RobustKernel kernel = RobustKernel::geman_mcclure(0.1);
  /// Converged when an iteration moves the correspondences' centroid less than this (m) ...
  double translation_tolerance = 1e-4;
  /// ... and turns by less than this (rad). The same test ends the steps of one iteration.
  double rotation_tolerance = 1e-5;
  std::size_t min_correspondences = 30;
  /// Directions of the scaled, centred Hessian (see registration_conditioning.hpp) whose
  /// eigenvalue is below this fraction of the largest are not updated, and the result is
  /// reported degenerate.
  double min_condition = 1e-3;
  /// |r| at most this counts as an inlier (reporting only; it does not change the estimate).
  double inlier_distance = 0.1;
  /// Source points per parallel chunk; fixed so sums do not depend on the thread count.
  std::size_t grain = 256;
};

enum class RegistrationStatus {
  ok,
  not_converged,            ///< max_iterations reached while the updates were still large
  too_few_correspondences,  ///< fewer than min_correspondences residuals at some iteration
  degenerate,               ///< some direction unconstrained (see min_condition)
  invalid_input             ///< empty source, non-finite initial pose or bad options
};

inline const char* to_string(RegistrationStatus s) {
  switch (s) {
    case RegistrationStatus::ok:
      return "ok";
    case RegistrationStatus::not_converged:
      return "not_converged";
    case RegistrationStatus::too_few_correspondences:
      return "too_few_correspondences";
    case RegistrationStatus::degenerate:
      return "degenerate";
    default:
      return "invalid_input";
  }
}

template <typename S>
struct RegistrationResult {
  RegistrationStatus status = RegistrationStatus::ok;
  const char* reason = "";
  Isometry3<S> pose = Isometry3<S>::Identity();  ///< T_target_source
  int iterations = 0;                            ///< correspondence searches
  int solver_iterations = 0;                     ///< Gauss-Newton steps, all searches
  std::size_t source_points = 0;                 ///< finite source points offered
  std::size_t correspondences = 0;               ///< at the final pose
  std::size_t inliers = 0;                       ///< at the final pose
  double cost = 0.0;                             ///< sum of rho(r) at the final pose
  double rmse = 0.0;                             ///< RMS of the inliers' residuals, m
  /// sum w J^T J at the final pose: left perturbation about the target origin, [rho; phi].
  Mat6d hessian = Mat6d::Zero();
  /// lambda_min / lambda_max of the scaled, centred Hessian at the final pose, in [0, 1].
  double condition = 0.0;

  bool ok() const { return status == RegistrationStatus::ok; }
  double inlier_ratio() const {
    return source_points ? static_cast<double>(inliers) / static_cast<double>(source_points) : 0.0;
  }
};

/// How a PlaneCloud (registration_target.hpp) finds its points' planes.
struct PlaneCloudOptions {
  std::size_t normal_k = 10;   ///< neighbours of the PCA
  double min_planarity = 0.5;  ///< (l2 - l1) / l2, normals.hpp
  bool use_cloud_normals = true;
};

}  // namespace ulc
