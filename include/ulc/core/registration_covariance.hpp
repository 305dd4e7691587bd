// The covariance of a point-to-plane registration's pose from its final problem
// (point_to_plane.hpp's residuals at the returned pose, cluster_covariance.hpp's delete-one-cluster
// jackknife of the M-estimator: each point's curvature psi'(r) J J^T and gradient w r J).
//
// Conventions this header owns:
//   - The pose T of register_point_to_plane_terms, perturbed on the left (T <- exp(xi) T,
//     xi = [rho; phi], m and rad): the covariance is of xi, in the frame T maps into.
//   - Residuals, weights and matches as the registration's: every source point is matched at T
//     with options' gate, weighted by the term weight times options' kernel.
//   - Clusters: the source points whose matched point z (target frame) falls in one cubic cell
//     of side cell_size share their errors (a surface the two clouds sample differently, a
//     modelling error of one wall); cell_size 0 treats every point as its own cluster (the
//     delete-one-point jackknife, right for independent point noise).
//   - nullopt when fewer than two clusters matched or leaving one out makes the problem
//     singular.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "ulc/core/cluster_covariance.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/registration_types.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

template <typename S, class Target>
std::optional<Mat6d> point_to_plane_covariance(
    const std::vector<PointToPlaneTerm<S, Target>>& terms, const Isometry3d& T,
    const RegistrationOptions& options, double cell_size) {
  PointToPlaneMatches matches;
  match_point_to_plane(terms, T, options.max_correspondence_distance, matches);
  ClusterJackknife<6> clusters;
  std::int64_t index = 0;
  Vec6d J;
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const auto& term = terms[t];
    if (matches[t].size() != term.size) continue;
    const PointToPlaneGeometry geometry(term.pre, T, term.post);
    for (std::size_t i = 0; i < term.size; ++i, ++index) {
      const PlaneMatch& plane = matches[t][i];
      if (plane.normal.squaredNorm() == 0.0) continue;
      const Vec3d y = geometry.pose_frame(term.points[i].template cast<double>());
      const Vec3d z = geometry.target_frame(y);
      const double r = geometry.residual(y, z, plane, &J);
      const double w = term.weight * options.kernel.weight(r);
      clusters.add(cell_size > 0.0 ? cell_key(z, cell_size) : index,
                   Mat6d(term.weight * options.kernel.curvature(r) * J * J.transpose()),
                   Vec6d((w * r) * J));
    }
  }
  return clusters.widened_covariance();
}

/// The same for one source cloud against one target (T = T_target_source).
template <typename S, class Target>
std::optional<Mat6d> point_to_plane_covariance(const std::vector<Vec3<S>>& source,
                                               const Target& target, const Isometry3d& T,
                                               const RegistrationOptions& options,
                                               double cell_size) {
  std::vector<PointToPlaneTerm<S, Target>> terms(1);
  terms[0].points = source.data();
  terms[0].size = source.size();
  terms[0].target = &target;
  return point_to_plane_covariance(terms, T, options, cell_size);
}

}  // namespace ulc
