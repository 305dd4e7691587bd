// The pose graph of HOTS: SE(3) variables (frame and submap poses of both LiDARs, the
// extrinsic) and relative-pose factors with analytic Jacobians. Solved by sparse_lm.hpp.
//
// Conventions this header owns:
//   - Variables are T_world_x (or the extrinsic C = T_base_target), perturbed on the LEFT:
//     T <- exp(d) T, d = [rho; phi] (lie.hpp).
//   - A factor ties variable `from` (placed through a constant right offset L, X = T_from L),
//     variable `to`, and a measurement Z of X^-1 T_to that is either a constant or a third
//     variable `measured_var`. Residual r = log(X^-1 T_to Z^-1) (6-vector, [rho; phi]); with
//     E = exp(r) its Jacobians are
//       dr/dd_to   =  J_l^-1(r) Ad(X^-1)
//       dr/dd_from = -J_l^-1(r) Ad(X^-1)
//       dr/dd_Z    = -J_l^-1(r) Ad(E)
//     (checked against central differences in tests/hots).
//   - Kinds of factor in HOTS: a window's BA result (Z = T_window_i, from = the window's first
//     frame), a cross-LiDAR registration of submaps (Z = T_suba_subb), and the extrinsic tie of a
//     pair of (nearly) simultaneous frames: X = T_world_a L with L the motion of a from its frame
//     time to b's, to = T_world_b, Z = the extrinsic variable C.
//   - Whitening: e = S r with S an upper-triangular square root of the information (S^T S = I).
//     Cost = 1/2 sum rho(|e|^2), rho the identity or Huber with threshold `huber` (on |e|).
//   - Nothing here throws or prints.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace hots {

using ulc::Isometry3d;
using ulc::Mat6d;
using ulc::Vec6d;

constexpr std::size_t kNoVariable = std::numeric_limits<std::size_t>::max();

struct PoseFactor {
  std::size_t from = 0;
  std::size_t to = 0;
  Isometry3d from_offset = Isometry3d::Identity();  ///< L: X = T_from * L
  Isometry3d measured = Isometry3d::Identity();     ///< Z, when measured_var is kNoVariable
  std::size_t measured_var = kNoVariable;           ///< a variable standing for Z
  Mat6d sqrt_information = Mat6d::Identity();       ///< S, with S^T S the information
  double huber = 0.0;                               ///< 0: plain least squares
  int kind = 0;                                     ///< caller's tag (statistics only)
};

/// An upper-triangular S with S^T S = information (the information is made symmetric and, if
/// needed, positive definite by lifting its eigenvalues to `floor` times the largest).
inline Mat6d sqrt_information(const Mat6d& information, double floor = 1e-9) {
  const Mat6d sym = 0.5 * (information + information.transpose());
  Eigen::LLT<Mat6d> llt(sym);
  if (llt.info() == Eigen::Success && llt.matrixL().toDenseMatrix().diagonal().minCoeff() > 0.0)
    return llt.matrixU();
  const Eigen::SelfAdjointEigenSolver<Mat6d> eig(sym);
  const double top = std::max(eig.eigenvalues().maxCoeff(), 1e-300);
  const Vec6d lifted = eig.eigenvalues().cwiseMax(floor * top);
  const Mat6d fixed = eig.eigenvectors() * lifted.asDiagonal() * eig.eigenvectors().transpose();
  llt.compute(0.5 * (fixed + fixed.transpose()));
  return llt.matrixU();
}

/// Diagonal information from standard deviations (m for the translation, rad for the rotation).
inline Mat6d isotropic_sqrt_information(double sigma_translation, double sigma_rotation) {
  Vec6d d;
  d << Vec6d::Constant(1.0).head<3>() / sigma_translation,
      Vec6d::Constant(1.0).head<3>() / sigma_rotation;
  return d.asDiagonal();
}

/// The residual and Jacobians of one factor (unwhitened).
struct FactorLinearization {
  Vec6d residual = Vec6d::Zero();
  Mat6d J_from = Mat6d::Zero();
  Mat6d J_to = Mat6d::Zero();
  Mat6d J_measured = Mat6d::Zero();  ///< zero when the measurement is a constant
};

inline Isometry3d factor_measurement(const PoseFactor& f, const std::vector<Isometry3d>& vars) {
  return f.measured_var == kNoVariable ? f.measured : vars[f.measured_var];
}

/// r = log(X^-1 T_to Z^-1) and, when `jacobians`, its derivatives (see the header comment).
inline FactorLinearization linearize_factor(const PoseFactor& f,
                                            const std::vector<Isometry3d>& vars,
                                            bool jacobians = true) {
  FactorLinearization out;
  const Isometry3d X_inv = (vars[f.from] * f.from_offset).inverse();
  const Isometry3d Z = factor_measurement(f, vars);
  const Isometry3d E = X_inv * vars[f.to] * Z.inverse();
  out.residual = ulc::se3_log(E);
  if (!jacobians) return out;
  const Mat6d Jl_inv = ulc::se3_left_jacobian_inverse(out.residual);
  out.J_to = Jl_inv * ulc::adjoint(X_inv);
  out.J_from = -out.J_to;
  if (f.measured_var != kNoVariable) out.J_measured = -Jl_inv * ulc::adjoint(E);
  return out;
}

/// Weight of the IRLS step for a whitened residual norm (1 inside the Huber threshold).
inline double huber_weight(double norm, double threshold) {
  if (!(threshold > 0.0) || norm <= threshold) return 1.0;
  return threshold / norm;
}

/// rho(|e|^2) of the cost (Huber: 2 k |e| - k^2 outside the threshold k).
inline double huber_cost(double sq_norm, double threshold) {
  if (!(threshold > 0.0)) return sq_norm;
  const double n = std::sqrt(sq_norm);
  return n <= threshold ? sq_norm : 2.0 * threshold * n - threshold * threshold;
}

/// The variables, which of them are held fixed, and the factors.
struct PoseGraph {
  std::vector<Isometry3d> variables;
  std::vector<bool> fixed;
  std::vector<PoseFactor> factors;

  std::size_t add_variable(const Isometry3d& T, bool hold_fixed = false) {
    variables.push_back(T);
    fixed.push_back(hold_fixed);
    return variables.size() - 1;
  }
  std::size_t add_factor(const PoseFactor& f) {
    factors.push_back(f);
    return factors.size() - 1;
  }

  /// 1/2 sum rho(|S r|^2) at the current variables.
  double cost() const {
    double sum = 0.0;
    for (const PoseFactor& f : factors) {
      const Vec6d e = f.sqrt_information * linearize_factor(f, variables, false).residual;
      sum += huber_cost(e.squaredNorm(), f.huber);
    }
    return 0.5 * sum;
  }

  /// Every index in range, no factor tying a variable to itself, finite poses.
  bool valid() const {
    if (fixed.size() != variables.size()) return false;
    for (const Isometry3d& T : variables)
      if (!T.matrix().allFinite()) return false;
    for (const PoseFactor& f : factors) {
      const std::size_t n = variables.size();
      if (f.from >= n || f.to >= n || f.from == f.to) return false;
      if (f.measured_var != kNoVariable &&
          (f.measured_var >= n || f.measured_var == f.from || f.measured_var == f.to))
        return false;
      if (!f.sqrt_information.allFinite() || !f.from_offset.matrix().allFinite() ||
          !f.measured.matrix().allFinite())
        return false;
    }
    return true;
  }
};

}  // namespace hots
