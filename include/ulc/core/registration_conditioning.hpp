// Conditioning of a 6-DoF registration: the Hessian seen from the correspondences' centre, in
// units that make rotation and translation comparable, and a Gauss-Newton solve that leaves
// unconstrained directions alone.
//
// Conventions this header owns:
//   - H and b are the normal equations of a left perturbation about the target origin,
//     xi = [rho; phi] (normal_equations.hpp, lie.hpp). Far from the origin that basis mixes
//     rotation into translation, so H is re-expressed for a perturbation about a centre c
//     (xi_world = Ad(translation c) xi_c) and the rotation part is scaled by a length L (a turn
//     phi moves points at distance L by L phi): xi_world = M xi', M = Ad(c) diag(I, I / L).
//     Then H' = M^T H M and b' = M^T b, all six parameters in metres.
//   - condition = lambda_min(H') / lambda_max(H'), in [0, 1]: the share of the strongest
//     direction's information that the weakest direction gets. A scene of planes facing every
//     way scores ~0.1; a corridor, a tunnel or a lone ground plane score ~0.
//   - solve_truncated solves H' xi' = -b' on the eigen-directions with
//     lambda >= min_condition * lambda_max only (the others get no update: they stay at the
//     initial guess instead of following noise), and maps the step back to xi_world.
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// M = Ad(translation c) * diag(I, I / L): maps a centred, scaled perturbation to xi_world.
inline Mat6d centred_scaling(const Vec3d& c, double L) {
  Mat6d M = Mat6d::Identity();
  const double inv_l = 1.0 / std::max(L, 1e-9);
  M.block<3, 3>(0, 3) = hat(c) * inv_l;
  M.block<3, 3>(3, 3) = Mat3d::Identity() * inv_l;
  return M;
}

struct ScaledSolve {
  Vec6d step = Vec6d::Zero();  ///< xi_world
  double condition = 0.0;      ///< lambda_min / lambda_max of H'
  int dropped = 0;             ///< directions left without update
};

/// lambda_min / lambda_max of M^T H M (0 for a zero or non-finite H).
inline double scaled_condition(const Mat6d& H, const Vec3d& c, double L) {
  const Mat6d M = centred_scaling(c, L);
  const Mat6d Hs = M.transpose() * H * M;
  if (!Hs.allFinite()) return 0.0;
  const Eigen::SelfAdjointEigenSolver<Mat6d> eig(Hs, Eigen::EigenvaluesOnly);
  const double hi = eig.eigenvalues()[5];
  if (!(hi > 0.0)) return 0.0;
  return std::max(eig.eigenvalues()[0], 0.0) / hi;
}

/// Gauss-Newton step H xi = -b restricted to the well-conditioned directions (see top).
inline ScaledSolve solve_truncated(const Mat6d& H, const Vec6d& b, const Vec3d& c, double L,
                                   double min_condition) {
  ScaledSolve out;
  const Mat6d M = centred_scaling(c, L);
  const Mat6d Hs = M.transpose() * H * M;
  const Vec6d bs = M.transpose() * b;
  if (!Hs.allFinite() || !bs.allFinite()) {
    out.dropped = 6;
    return out;
  }
  const Eigen::SelfAdjointEigenSolver<Mat6d> eig(Hs);
  const Vec6d lambda = eig.eigenvalues();  // ascending
  const double hi = lambda[5];
  if (!(hi > 0.0)) {
    out.dropped = 6;
    return out;
  }
  out.condition = std::max(lambda[0], 0.0) / hi;
  Vec6d step_scaled = Vec6d::Zero();
  for (int i = 0; i < 6; ++i) {
    if (lambda[i] < min_condition * hi || !(lambda[i] > 0.0)) {
      ++out.dropped;
      continue;
    }
    const Vec6d v = eig.eigenvectors().col(i);
    step_scaled -= v * (v.dot(bs) / lambda[i]);
  }
  out.step = M * step_scaled;
  return out;
}

}  // namespace ulc
