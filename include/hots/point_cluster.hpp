// Point clusters and the plane cost of bundle adjustment (the BALM family, paper Sec.
// "Pose Refinement by Hierarchical Optimization"): a plane's cost is read from per-frame sums
// (sum p, sum p p^T, count), never from raw points.
//
// Conventions this header owns:
//   - A PointCluster holds, in double, the sums of (p - anchor) and (p - anchor)(p - anchor)^T
//     of its points and their count. Sums around a nearby anchor keep their digits: a
//     covariance summed in raw coordinates far from the origin loses them to cancellation.
//   - A plane is observed by several frames; frame i contributes the cluster of its points in
//     its own (body) frame and is placed in the plane's frame by its pose T_i. The merged
//     cluster is summed around the plane's anchor c (a point near the plane).
//   - Plane cost f = N * lambda_min(C) = lambda_min(M), with C the covariance of all merged
//     points and M = N C their scatter: the sum of squared distances of the points to their
//     best-fitting plane.
//   - Derivatives are with respect to LEFT perturbations of each pose, T_i <- exp(xi_i) T_i,
//     xi = [rho; phi] (lie.hpp). Gradient: df = u^T dM u (u the eigenvector of lambda_min).
//     Hessian: the second-order term of dM plus the coupling through the other eigenpairs,
//     2 sum_k (u_k^T dM_a u)(u_k^T dM_b u) / (lambda_min - lambda_k). Both are exact at any
//     pose (checked against central differences in tests/hots).
//   - Guard: when lambda_min is within `min_gap` of the next eigenvalue the eigenvector is not
//     defined; evaluate_plane() then reports degenerate and returns no derivatives.
//   - Nothing here throws, prints or allocates beyond the caller's vectors.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstddef>
#include <vector>

#include "hots/options.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace hots {

using ulc::Isometry3d;
using ulc::Mat3d;
using ulc::Mat6d;
using ulc::Vec3d;
using ulc::Vec6d;

/// Sums of points around an anchor, in double.
struct PointCluster {
  Vec3d anchor = Vec3d::Zero();
  Mat3d sum_outer = Mat3d::Zero();  ///< sum (p - anchor)(p - anchor)^T
  Vec3d sum = Vec3d::Zero();        ///< sum (p - anchor)
  double count = 0.0;

  PointCluster() = default;
  explicit PointCluster(const Vec3d& anchor_point) : anchor(anchor_point) {}

  /// Adds a point; the first point of an empty cluster becomes its anchor when none was set.
  template <typename S>
  void add(const ulc::Vec3<S>& p_in) {
    const Vec3d p = p_in.template cast<double>();
    if (count == 0.0 && sum_outer.isZero(0.0) && anchor.isZero(0.0)) anchor = p;
    const Vec3d d = p - anchor;
    sum_outer.noalias() += d * d.transpose();
    sum += d;
    count += 1.0;
  }

  /// Mean of the points.
  Vec3d mean() const { return count > 0.0 ? Vec3d(anchor + sum / count) : anchor; }

  /// Scatter matrix sum (p - mean)(p - mean)^T.
  Mat3d scatter() const {
    if (!(count > 0.0)) return Mat3d::Zero();
    return sum_outer - sum * sum.transpose() / count;
  }

  /// The same points moved by T, summed around `new_anchor`.
  PointCluster transformed(const Isometry3d& T, const Vec3d& new_anchor) const {
    PointCluster out(new_anchor);
    const Mat3d& R = T.linear();
    // x = R (p - a) + (R a + t - new_anchor): the sums of the shifted, rotated points.
    const Vec3d shift = R * anchor + T.translation() - new_anchor;
    const Vec3d rs = R * sum;
    out.sum_outer = R * sum_outer * R.transpose() + rs * shift.transpose() +
                    shift * rs.transpose() + count * shift * shift.transpose();
    out.sum = rs + count * shift;
    out.count = count;
    return out;
  }

  /// Adds another cluster summed around the same anchor.
  PointCluster& operator+=(const PointCluster& o) {
    sum_outer += o.sum_outer;
    sum += o.sum;
    count += o.count;
    return *this;
  }
};

/// One frame's view of a plane: which pose and the cluster of its points in its body frame.
struct FrameCluster {
  std::size_t frame = 0;
  PointCluster cluster;
};

/// Eigen-decomposition of a plane's scatter, smallest eigenvalue first.
struct PlaneEigen {
  Vec3d values = Vec3d::Zero();   ///< ascending
  Mat3d vectors = Mat3d::Zero();  ///< columns, matching values
};

inline PlaneEigen plane_eigen(const Mat3d& scatter) {
  const Eigen::SelfAdjointEigenSolver<Mat3d> solver(scatter);
  return {solver.eigenvalues(), solver.eigenvectors()};
}

/// The merged cluster of a plane's frames placed by their poses, around anchor c.
inline PointCluster merge_plane(const std::vector<FrameCluster>& frames,
                                const std::vector<Isometry3d>& poses, const Vec3d& c) {
  PointCluster merged(c);
  for (const FrameCluster& f : frames) merged += f.cluster.transformed(poses[f.frame], c);
  return merged;
}

/// Plane cost lambda_min(M) at the given poses (see the header comment).
inline double plane_cost(const std::vector<FrameCluster>& frames,
                         const std::vector<Isometry3d>& poses, const Vec3d& c) {
  const Mat3d M = merge_plane(frames, poses, c).scatter();
  const Eigen::SelfAdjointEigenSolver<Mat3d> solver(M, Eigen::EigenvaluesOnly);
  return solver.eigenvalues()(0);
}

/// Cost, gradient and Hessian of one plane with respect to the poses of its frames (in the
/// order of `frames`): gradient[k] is df/dxi of frames[k], hessian is 6K x 6K.
struct PlaneDerivatives {
  double cost = 0.0;
  bool degenerate = false;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd hessian;
};

/// A plane's derivatives in factored form: per frame a, the forms w_a (6 x 3: w_a,k = u_k^T
/// (dM/dxi_a) u, column 0 the gradient), e_a = d(u . s)/dxi_a and the second-order block of
/// its own points, all for perturbations about the origin. The Hessian is
///   H_ab = -2 e_a e_b^T / N + sum_k=1,2 2 w_a,k w_b,k^T / (lambda_0 - lambda_k) + [a = b] own_a,
/// so a caller whose frames hang on other variables (sweep_ba.hpp) maps the forms by its
/// Jacobians and sums the outer products there, in O(frames) instead of O(frames^2).
struct PlaneForms {
  double cost = 0.0;
  bool degenerate = false;
  double count = 0.0;            ///< N
  Vec3d values = Vec3d::Zero();  ///< eigenvalues, ascending
  std::vector<Eigen::Matrix<double, 6, 3>> w;
  std::vector<Vec6d> e;
  std::vector<Mat6d> own;
};

/// See the header comment. The derivation works with the points around c, x = T p - c, where
/// a left perturbation of T about the origin is the perturbation [rho + phi x c; phi] about c;
/// the chain rule through that linear map G = [[I, -[c]x], [0, I]] brings the result back.
inline PlaneForms plane_forms(const std::vector<FrameCluster>& frames,
                              const std::vector<Isometry3d>& poses, const Vec3d& c,
                              const PlaneEvaluationOptions& options = {}) {
  const std::size_t K = frames.size();
  PlaneForms out;
  // Each frame's points placed around c.
  std::vector<PointCluster> placed;
  placed.reserve(K);
  PointCluster merged(c);
  for (const FrameCluster& f : frames) {
    placed.push_back(f.cluster.transformed(poses[f.frame], c));
    merged += placed.back();
  }
  if (!(merged.count > 0.0)) {
    out.degenerate = true;
    return out;
  }
  const double N = merged.count;
  const Mat3d M = merged.scatter();
  const PlaneEigen eig = plane_eigen(M);
  out.cost = eig.values(0);
  out.count = N;
  out.values = eig.values;
  const double gap = eig.values(1) - eig.values(0);
  if (!(gap > options.min_gap * (M.trace() + 1e-300))) {
    out.degenerate = true;
    return out;
  }
  const Vec3d u = eig.vectors.col(0);
  const Vec3d mu = merged.sum / N;
  const double u_mu = u.dot(mu);
  Mat6d G = Mat6d::Identity();
  G.topRightCorner<3, 3>() = -ulc::hat(c);
  out.w.resize(K);
  out.e.resize(K);
  out.own.resize(K);
  for (std::size_t a = 0; a < K; ++a) {
    const PointCluster& P = placed[a];
    const Vec3d Au = P.sum_outer * u;
    Eigen::Matrix<double, 6, 3> w;
    for (int k = 0; k < 3; ++k) {
      const Vec3d uk = eig.vectors.col(k);
      const Vec3d Auk = P.sum_outer * uk;
      const double uk_mu = uk.dot(mu);
      Vec6d col;
      col.head<3>() = uk * (u.dot(P.sum) - P.count * u_mu) + u * (uk.dot(P.sum) - P.count * uk_mu);
      col.tail<3>() = Au.cross(uk) + Auk.cross(u) - P.sum.cross(uk) * u_mu - P.sum.cross(u) * uk_mu;
      w.col(k) = col;
    }
    Vec6d e;
    e.head<3>() = P.count * u;
    e.tail<3>() = P.sum.cross(u);
    // Second-order terms of frame a's own points.
    const Mat3d U = ulc::hat(u);
    const Vec3d su = P.sum.cross(u);
    Mat6d own = Mat6d::Zero();
    own.topLeftCorner<3, 3>() = 2.0 * P.count * u * u.transpose();
    own.topRightCorner<3, 3>() = 2.0 * u * su.transpose();
    own.bottomLeftCorner<3, 3>() = 2.0 * su * u.transpose();
    own.bottomRightCorner<3, 3>() = 2.0 * U * P.sum_outer * U.transpose();
    const Mat3d B3 =
        u * (Au - u_mu * P.sum).transpose() - (u.dot(Au) - u_mu * u.dot(P.sum)) * Mat3d::Identity();
    own.bottomRightCorner<3, 3>() += B3 + B3.transpose();
    const double beta = u.dot(P.sum) - P.count * u_mu;
    const Mat3d D = -beta * U;  // d^2 / dphi drho
    own.bottomLeftCorner<3, 3>() += D;
    own.topRightCorner<3, 3>() += D.transpose();
    // Back from perturbations about c to perturbations about the origin: xi_c = G xi.
    out.w[a] = G.transpose() * w;
    out.e[a] = G.transpose() * e;
    out.own[a] = G.transpose() * own * G;
  }
  return out;
}

/// A frame's (or a mapped variable's) forms scaled so that the cross term of its Hessian block
/// with another's is -Z_a Z_b^T: Z = [sqrt(2 / N) e, sqrt(2 / (lambda_1 - lambda_0)) w_1,
/// sqrt(2 / (lambda_2 - lambda_0)) w_2]. All three coefficients of the header comment's H_ab
/// are negative, so a plane's cross terms over its variables are one rank-3 update, and each
/// variable's factor is computed once instead of once per pair. f must not be degenerate.
inline Eigen::Matrix<double, 6, 3> hessian_factor(const PlaneForms& f,
                                                  const Eigen::Matrix<double, 6, 3>& w,
                                                  const Vec6d& e) {
  Eigen::Matrix<double, 6, 3> Z;
  Z.col(0) = std::sqrt(2.0 / f.count) * e;
  for (int k = 1; k < 3; ++k) Z.col(k) = std::sqrt(2.0 / (f.values(k) - f.values(0))) * w.col(k);
  return Z;
}

/// H(a, b) -= Za Zb^T and, for a pair of distinct variables (mirror), its transpose at (b, a).
inline void subtract_cross_terms(Eigen::MatrixXd& H, Eigen::Index a, Eigen::Index b,
                                 const Eigen::Matrix<double, 6, 3>& Za,
                                 const Eigen::Matrix<double, 6, 3>& Zb, bool mirror) {
  const Mat6d block = Za * Zb.transpose();
  H.block<6, 6>(a, b) -= block;
  if (mirror) H.block<6, 6>(b, a) -= block.transpose();
}

/// The Hessian block between two frames (or two mapped variables) from their forms, without
/// frame a's own second-order term.
inline Mat6d plane_hessian_block(const PlaneForms& f, const Eigen::Matrix<double, 6, 3>& wa,
                                 const Vec6d& ea, const Eigen::Matrix<double, 6, 3>& wb,
                                 const Vec6d& eb) {
  return -(hessian_factor(f, wa, ea) * hessian_factor(f, wb, eb).transpose());
}

/// Cost, gradient and Hessian of one plane (see the header comment and PlaneForms).
inline PlaneDerivatives evaluate_plane(const std::vector<FrameCluster>& frames,
                                       const std::vector<Isometry3d>& poses, const Vec3d& c,
                                       const PlaneEvaluationOptions& options = {}) {
  const std::size_t K = frames.size();
  PlaneDerivatives out;
  out.gradient = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(6 * K));
  out.hessian =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(6 * K), static_cast<Eigen::Index>(6 * K));
  const PlaneForms f = plane_forms(frames, poses, c, options);
  out.cost = f.cost;
  out.degenerate = f.degenerate;
  if (f.degenerate) return out;
  for (std::size_t a = 0; a < K; ++a) {
    const auto ia = static_cast<Eigen::Index>(6 * a);
    out.gradient.segment<6>(ia) = f.w[a].col(0);
    for (std::size_t b = 0; b < K; ++b)
      out.hessian.block<6, 6>(ia, static_cast<Eigen::Index>(6 * b)) =
          plane_hessian_block(f, f.w[a], f.e[a], f.w[b], f.e[b]);
    out.hessian.block<6, 6>(ia, ia) += f.own[a];
  }
  return out;
}

}  // namespace hots
