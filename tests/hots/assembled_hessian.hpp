// The reference Hessian of a BA window for the evaluate() tests: each plane's dense Hessian over
// its entries (evaluate_plane, checked against central differences in test_point_cluster)
// mapped into the variables term by term.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "hots/plane_extraction.hpp"
#include "hots/point_cluster.hpp"

namespace hots_test {

/// sum over planes and entry pairs (a, b) of M_a^T H_ab M_b, symmetrised; to_variables[e] is
/// entry e's 6 x 6V map into the variables (a selection of its block for a rigid frame).
inline Eigen::MatrixXd assembled_hessian(const std::vector<hots::Plane>& planes,
                                         const std::vector<ulc::Isometry3d>& entry_poses,
                                         const hots::PlaneEvaluationOptions& evaluation,
                                         const std::vector<Eigen::MatrixXd>& to_variables) {
  const Eigen::Index n = to_variables.empty() ? 0 : to_variables.front().cols();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  for (const hots::Plane& plane : planes) {
    const hots::PlaneDerivatives d =
        hots::evaluate_plane(plane.frames, entry_poses, plane.anchor, evaluation);
    if (d.degenerate) continue;
    for (std::size_t a = 0; a < plane.frames.size(); ++a)
      for (std::size_t b = 0; b < plane.frames.size(); ++b)
        H += to_variables[plane.frames[a].frame].transpose() *
             d.hessian.block<6, 6>(static_cast<Eigen::Index>(6 * a),
                                   static_cast<Eigen::Index>(6 * b)) *
             to_variables[plane.frames[b].frame];
  }
  return 0.5 * (H + H.transpose());
}

}  // namespace hots_test
