// A refinement baseline for the refinement table: Generalized-ICP (Segal, Haehnel and Thrun,
// "Generalized-ICP", RSS 2009) in its plane-to-plane form, written for bench_jeep only (the
// library has no GICP; PCL and Open3D are not dependencies). What it does:
//   - the caller prepares both clouds (bench_jeep: as scan-scan does, odometry::prepare_scan with
//     jeep::ScanScanOptions' scan options, so the baselines on one frame pair see the same points);
//   - every point of both clouds gets a covariance from its k nearest neighbours in its own
//     cloud (k = 20), regularised as the paper's plane-to-plane model:
//     C = I - (1 - eps) n n^T, n the neighbourhood's normal (ulc::estimate_normals: the
//     eigenvector of the smallest eigenvalue), eps = 1e-3: each point is a small disc on its
//     local plane, certain along the normal and uncertain within the plane. This is the paper's
//     V diag(eps, 1, 1) V^T written with the normal alone (V's other two columns span the plane);
//     a neighbourhood with no plane (fewer than 3 points, coincident or collinear) is isotropic;
//   - each iteration re-matches every source point a_i, moved by the current T, to its nearest
//     target point b_i within the stage's correspondence distance, and minimises the paper's
//     maximum-likelihood objective sum_i d_i^T (C_b_i + R C_a_i R^T)^-1 d_i with d_i = b_i - T a_i,
//     by one Levenberg-Marquardt step over SE(3) (the weights fixed within the step, as in the
//     usual implementations; the paper used conjugate gradients);
//   - the correspondence distance shrinks over stages (4, 1.5, 0.6, 0.3 m by default: the gates
//     of scan-scan's and JEEP's registration stages, jeep/options.hpp, so the two baselines on
//     one frame pair differ in their cost, not in how far they look for partners);
//   - a stage ends when an update moves T by less than the tolerances or after max_iterations;
//     the result is converged when the last stage ended on a small update (which needs enough
//     matches in that iteration).
// Conventions: the library's (ulc/core/lie.hpp), a left perturbation T <- exp(xi) T with
// xi = [rho; phi]; the pose is T_target_source (p_target = T * p_source). No randomness; the
// per-point searches run in parallel but every sum is taken in point order: the same input
// gives the same answer on any number of threads.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "ulc/core/kdtree.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/normals.hpp"
#include "ulc/core/types.hpp"

namespace gicp_baseline {

using ulc::Isometry3d;
using ulc::Mat3d;
using ulc::Mat6d;
using ulc::Vec3d;
using ulc::Vec6d;
using Points = std::vector<Vec3d>;

struct Options {
  std::size_t covariance_neighbours = 20;  ///< k of each point's covariance (the paper: 20)
  double epsilon = 1e-3;                   ///< the normal's variance against 1 in the plane
  std::vector<double> gates = {4.0, 1.5, 0.6, 0.3};  ///< m, correspondence distance per stage
  int max_iterations = 30;                           ///< per stage
  double translation_tolerance = 1e-4;               ///< m, an update this small ends a stage
  double rotation_tolerance = 1e-5;                  ///< rad
  std::size_t min_correspondences = 50;              ///< fewer: the stage (and the result) fails
};

struct Result {
  bool converged = false;
  Isometry3d pose = Isometry3d::Identity();  ///< T_target_source
  int iterations = 0;                        ///< over all stages
  std::size_t correspondences = 0;           ///< of the last iteration
  double cost = 0.0;                         ///< the objective over them, at the returned pose
};

namespace detail {

/// One correspondence: source point i, target point j.
struct Match {
  std::size_t i, j;
};

/// The plane-to-plane covariance of a point with unit normal n (Segal et al.):
/// I - (1 - eps) n n^T, variance eps along the normal and 1 within the plane.
inline Mat3d plane_covariance(const Vec3d& normal, double epsilon) {
  return Mat3d::Identity() - (1.0 - epsilon) * normal * normal.transpose();
}

/// Every point's covariance from the normal of its k nearest neighbours in its own cloud (itself
/// included); isotropic where estimate_normals finds no plane. Each point's result depends on
/// nothing else, so threads do not change it.
inline std::vector<Mat3d> covariances(const Points& points, const ulc::KdTree<Points>& tree,
                                      const Options& o) {
  ulc::NormalEstimationOptions normal_options;
  normal_options.k = o.covariance_neighbours;
  const auto normals = ulc::estimate_normals(points, tree, normal_options);
  std::vector<Mat3d> out(points.size(), Mat3d::Identity());
  if (!normals.ok()) return out;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (normals.points[i].valid) out[i] = plane_covariance(normals.points[i].normal, o.epsilon);
  return out;
}

/// Nearest target point of each moved source point, within `gate` (re-done every iteration).
/// Searched per point (in parallel), kept in source order: the same list for any thread count.
inline std::vector<Match> match(const Points& source, const ulc::KdTree<Points>& target_tree,
                                const Isometry3d& T, double gate) {
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> nearest(source.size(), kNone);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, source.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        std::size_t j = 0;
                        double sq = 0.0;
                        if (target_tree.nearest(T * source[i], j, sq) && sq <= gate * gate)
                          nearest[i] = j;
                      }
                    });
  std::vector<Match> out;
  for (std::size_t i = 0; i < source.size(); ++i)
    if (nearest[i] != kNone) out.push_back({i, nearest[i]});
  return out;
}

/// (C_b + R C_a R^T)^-1 of each match at rotation R: the objective's weights, held fixed in a step.
inline std::vector<Mat3d> information(const std::vector<Match>& matches,
                                      const std::vector<Mat3d>& source_cov,
                                      const std::vector<Mat3d>& target_cov, const Mat3d& R) {
  std::vector<Mat3d> out(matches.size());
  for (std::size_t m = 0; m < matches.size(); ++m) {
    const Mat3d combined = target_cov[matches[m].j] + R * source_cov[matches[m].i] * R.transpose();
    out[m] = combined.inverse();  // symmetric positive definite: C_b's eigenvalues >= eps
  }
  return out;
}

/// The objective: sum_i d_i^T W_i d_i, d_i = b_i - T a_i.
inline double cost(const Points& source, const Points& target, const std::vector<Match>& matches,
                   const std::vector<Mat3d>& W, const Isometry3d& T) {
  double sum = 0.0;
  for (std::size_t m = 0; m < matches.size(); ++m) {
    const Vec3d d = target[matches[m].j] - T * source[matches[m].i];
    sum += d.dot(W[m] * d);
  }
  return sum;
}

/// Gauss-Newton normal equations of the objective at T for a left perturbation exp(xi) T:
/// d_i(xi) ~= d_i - rho + [q_i]x phi with q_i = T a_i, so J_i = [-I, [q_i]x].
inline void normal_equations(const Points& source, const Points& target,
                             const std::vector<Match>& matches, const std::vector<Mat3d>& W,
                             const Isometry3d& T, Mat6d& H, Vec6d& g) {
  H.setZero();
  g.setZero();
  Eigen::Matrix<double, 3, 6> J;
  for (std::size_t m = 0; m < matches.size(); ++m) {
    const Vec3d q = T * source[matches[m].i];
    const Vec3d d = target[matches[m].j] - q;
    J.leftCols<3>() = -Mat3d::Identity();
    J.rightCols<3>() = ulc::hat(q);
    H.noalias() += J.transpose() * W[m] * J;
    g.noalias() += J.transpose() * W[m] * d;
  }
}

/// A step's update and the objective at the pose it leaves.
struct Step {
  Vec6d xi;
  double cost;
};

/// One Levenberg-Marquardt step over fixed matches and weights: the damping grows until the
/// step lowers the objective (and shrinks after a success). Returns the update taken (zero when
/// no step lowers the cost: a minimum for these matches; NaN when the equations are singular)
/// and the cost at the resulting T.
inline Step lm_step(const Points& source, const Points& target, const std::vector<Match>& matches,
                    const std::vector<Mat3d>& W, Isometry3d& T, double& lambda) {
  Mat6d H;
  Vec6d g;
  normal_equations(source, target, matches, W, T, H, g);
  const double before = cost(source, target, matches, W, T);
  for (int attempt = 0; attempt < 10; ++attempt) {
    Mat6d damped = H;
    damped.diagonal() += lambda * H.diagonal();
    const Vec6d xi = damped.ldlt().solve(-g);
    if (!xi.allFinite()) return {Vec6d::Constant(std::numeric_limits<double>::quiet_NaN()), before};
    const Isometry3d candidate = ulc::se3_exp(xi) * T;
    const double after = cost(source, target, matches, W, candidate);
    if (after <= before) {
      T = candidate;
      lambda = std::max(lambda / 10.0, 1e-9);
      return {xi, after};
    }
    lambda *= 10.0;
  }
  return {Vec6d::Zero(), before};
}

/// Iterations of one stage (one gate). True when it ended on a small update; false after
/// max_iterations, with too few matches or singular equations.
inline bool run_stage(const Points& source, const Points& target,
                      const ulc::KdTree<Points>& target_tree, const std::vector<Mat3d>& source_cov,
                      const std::vector<Mat3d>& target_cov, double gate, const Options& o,
                      Result& r) {
  double lambda = 1e-6;
  for (int it = 0; it < o.max_iterations; ++it) {
    const auto matches = match(source, target_tree, r.pose, gate);
    r.correspondences = matches.size();
    if (matches.size() < o.min_correspondences) return false;
    const auto W = information(matches, source_cov, target_cov, r.pose.linear());
    ++r.iterations;
    const auto [xi, cost_after] = lm_step(source, target, matches, W, r.pose, lambda);
    if (!xi.allFinite()) return false;
    r.cost = cost_after;
    if (xi.head<3>().norm() < o.translation_tolerance && xi.tail<3>().norm() < o.rotation_tolerance)
      return true;
  }
  return false;
}

}  // namespace detail

/// GICP of `source` onto `target` from `initial` (both clouds prepared by the caller): the pose
/// T_target_source.
inline Result gicp(const Points& source, const Points& target, const Isometry3d& initial,
                   const Options& o = {}) {
  Result r;
  r.pose = initial;
  if (source.size() < o.min_correspondences || target.size() < o.min_correspondences ||
      !initial.matrix().allFinite() || o.gates.empty())
    return r;
  const ulc::KdTree<Points> source_tree(source), target_tree(target);
  const auto source_cov = detail::covariances(source, source_tree, o);
  const auto target_cov = detail::covariances(target, target_tree, o);
  for (double gate : o.gates)
    r.converged =
        detail::run_stage(source, target, target_tree, source_cov, target_cov, gate, o, r);
  return r;
}

}  // namespace gicp_baseline
