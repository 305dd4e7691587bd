// Which directions of an extrinsic the data cannot pin down, as vectors and in words.
//
// Conventions this header owns:
//   - Input: the 6x6 information (Gauss-Newton normal matrix H = sum w J J^T) of a left
//     perturbation of the extrinsic in the base frame, xi = [rho; phi] (lie.hpp), and the
//     centroid c and covariance Sigma of the points that made it. H is re-expressed as
//     H' = M^T H M with M = Ad(translation c) diag(I, S^-1), S = (tr(Sigma) I - Sigma)^(1/2):
//     a turn is taken about c, and measured by how far it moves the points (S phi: the RMS
//     displacement, in metres, of the points turned by phi about c, axis by axis), so that
//     translation and rotation are both in metres and a rotation is neither confused with the
//     translation it causes far from the origin nor judged by a lever the points do not have.
//     The isotropic length of registration_conditioning.hpp (S = L I) made the roll of a Tele-15
//     about its own narrow beam look 50 times weaker than it is (64-tele: share 0.005, as low as
//     the highway's road direction; docs/experiments/degenerate_scenes.md).
//   - share of an eigen-direction = its eigenvalue of H' over the largest, in [0, 1]. A direction
//     is unobservable when its share is below max_share: the information along it is that small
//     a part of the best-pinned one's, so noise and the scene's few irregularities decide where
//     the registration ends along it.
//   - Each unobservable direction is reported as its unit eigenvector v = [t; r] of H' (t the
//     translation in metres, r = S phi the turn's displacement in metres), its sign chosen so
//     that its largest component is positive, and in words naming the dominant axis or axes of
//     the base frame (of t, and of the turn's axis phi = S^-1 r).
//   - max_share = 0.01, measured on whole calibrations (docs/experiments/degenerate_scenes.md):
//     the highway's road direction had 0.0017-0.0023; every right answer's whole-drive problem
//     >= 0.05 (the main 64-horizon demo 0.076, 64-tele 0.071), the real croon_0003 snapshot
//     0.117.
//   - Nothing here throws (the words are built with std::string).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "ulc/core/lie.hpp"
#include "ulc/core/observability_types.hpp"
#include "ulc/core/registration_conditioning.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

struct ObservabilityOptions {
  double max_share = 0.01;  ///< see the conventions: a direction below it is unobservable
};

namespace observability_detail {

/// "x", "x and y" or "x, y and z": the axes carrying at least a third of a unit vector's
/// length (at least the largest), with the vector itself when it is not a single axis.
inline std::string axis_words(const Vec3d& a) {
  const double n = a.norm();
  if (!(n > 0.0)) return "no axis";
  const Vec3d u = a / n;
  static const char* const kNames[3] = {"x", "y", "z"};
  std::vector<int> axes;
  Eigen::Index largest = 0;
  u.cwiseAbs().maxCoeff(&largest);
  for (int i = 0; i < 3; ++i)
    if (i == largest || std::abs(u[i]) >= 1.0 / 3.0) axes.push_back(i);
  if (axes.size() == 1 && std::abs(u[largest]) >= 0.95) return kNames[largest];
  std::string out;
  for (std::size_t k = 0; k < axes.size(); ++k)
    out += std::string(k == 0 ? "" : (k + 1 == axes.size() ? " and " : ", ")) + kNames[axes[k]];
  Vec3d s = u[largest] < 0.0 ? Vec3d(-u) : u;
  for (int i = 0; i < 3; ++i)
    if (std::abs(s[i]) < 0.005) s[i] = 0.0;  // no "-0.00"
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, " (%.2f, %.2f, %.2f)", s.x(), s.y(), s.z());
  return out + buffer;
}

}  // namespace observability_detail

/// The sentence for a unit direction [t; r] of the centred, scaled basis; `axis` is the turn's
/// axis (S^-1 r).
inline std::string direction_words(const Vec6d& v, const Vec3d& axis) {
  using observability_detail::axis_words;
  const Vec3d t = v.head<3>(), r = v.tail<3>();
  const double t2 = t.squaredNorm(), r2 = r.squaredNorm();
  if (t2 >= 0.75)
    return "translation along " + axis_words(t) +
           " of the base frame is unobservable: the scene is the same along it";
  if (r2 >= 0.75)
    return "rotation about " + axis_words(axis) +
           " of the base frame is unobservable: the scene is the same turned about it";
  return "translation along " + axis_words(t) + " together with rotation about " +
         axis_words(axis) +
         " of the base frame is unobservable: the scene is the same along that screw motion";
}

/// S = (tr(Sigma) I - Sigma)^(1/2): the RMS displacement of the points per radian of turn about
/// each axis through their centroid (see the conventions), floored at 1e-6 of the largest.
inline Mat3d turn_levers(const Mat3d& covariance) {
  const Mat3d inertia = Mat3d::Identity() * covariance.trace() - covariance;
  const Eigen::SelfAdjointEigenSolver<Mat3d> eig(0.5 * (inertia + inertia.transpose()));
  const double top = std::max(eig.eigenvalues()[2], 1e-18);
  const Vec3d lever = eig.eigenvalues().cwiseMax(1e-12 * top).cwiseSqrt();
  return eig.eigenvectors() * lever.asDiagonal() * eig.eigenvectors().transpose();
}

/// The eigen-directions of H' = M^T H M (see the conventions) whose share is below
/// options.max_share, weakest first. A zero or non-finite H has every direction unobservable.
inline Observability observability(const Mat6d& H, const Vec3d& centre, const Mat3d& covariance,
                                   const ObservabilityOptions& options = {}) {
  Observability out;
  out.centre = centre;
  const Mat3d S = covariance.allFinite() ? turn_levers(covariance) : Mat3d::Identity();
  const Mat3d S_inv = S.inverse();
  out.length = std::sqrt(std::max(covariance.trace(), 0.0));
  Mat6d M = Mat6d::Identity();
  M.block<3, 3>(0, 3) = hat(centre) * S_inv;
  M.block<3, 3>(3, 3) = S_inv;
  Mat6d Hs = M.transpose() * H * M;
  if (!Hs.allFinite()) Hs.setZero();
  const Eigen::SelfAdjointEigenSolver<Mat6d> eig(0.5 * (Hs + Hs.transpose()));
  const Vec6d lambda = eig.eigenvalues();  // ascending
  const double top = lambda[5];
  for (int i = 0; i < 6; ++i) out.shares[i] = top > 0.0 ? std::max(lambda[i], 0.0) / top : 0.0;
  out.weakest_share = out.shares[0];
  for (int i = 0; i < 6 && out.shares[i] < options.max_share; ++i) {
    UnobservableDirection d;
    d.vector = eig.eigenvectors().col(i);
    Eigen::Index largest = 0;
    d.vector.cwiseAbs().maxCoeff(&largest);
    if (d.vector[largest] < 0.0) d.vector = -d.vector;
    d.share = out.shares[i];
    d.words = direction_words(d.vector, S_inv * d.vector.tail<3>());
    out.unobservable.push_back(std::move(d));
  }
  return out;
}

/// The same information seen from the other side of an extrinsic: H_a for a left perturbation
/// of C = T_a_b in frame a, from H_b for a left perturbation of C^-1 in frame b
/// (C^-1 exp(xi_b) inverted is exp(-Ad_C xi_b) C, so xi_a = -Ad_C xi_b); the points' centroid
/// moves to C c and their covariance turns to R Sigma R^T. The shares do not change; the
/// directions turn by C's rotation.
inline Mat6d information_in_base(const Mat6d& H_b, const Isometry3d& C) {
  const Mat6d Ad_inv = adjoint(Isometry3d(C.inverse()));
  return Ad_inv.transpose() * H_b * Ad_inv;
}

}  // namespace ulc
