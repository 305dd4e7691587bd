// The pieces of the whole-sequence step (sequence_extrinsic.hpp): the base's submaps as its
// targets, one point's residual with its Jacobian in C and the clock offset dt, the step taken
// in the 7 parameters, and dt's standard deviation and observability.
//
// Conventions this header owns:
//   - World = the frame of the base's poses world_a (T_world_a at times_a, a's clock). Clock
//     offset as in docs/design.md: t_a = t_b + dt. T_a(t) interpolates world_a (slerp + linear).
//   - Targets: the base's layer-`target_layer` submaps of the hierarchy (clouds anchored at
//     their first frame), voxel-thinned at target_voxel, with PCA planes. Frame j's points go
//     to the submap whose time span holds t_j + dt (else the nearest), as one point-to-plane
//     term with post = T_world_anchor^-1 T_a(t_j + dt) around the estimated C (left
//     perturbation, point_to_plane.hpp).
//   - The residual of a point x of b's frame j: n . (post y - q), y = C x, with the matched
//     plane (n, q) of the submap; its Jacobian is [u; y x u; n . (d post / d dt) y], u = post's
//     rotation^T n, for C <- exp(xi) C and dt.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hots/hierarchy.hpp"
#include "hots/options.hpp"
#include "hots/time_sync.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/registration_target.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace hots {

namespace sequence_detail {

template <typename S>
using Target = ulc::PlaneCloud<S>;

/// The base's submaps with planes, and each one's anchor frame and time span.
template <typename S>
struct BaseSubmaps {
  std::vector<Target<S>> planes;
  std::vector<std::size_t> anchor;
  std::vector<double> start, end;  ///< a's clock

  /// The submap whose span holds t, else the nearest.
  std::size_t at(double t) const {
    const auto it = std::upper_bound(start.begin(), start.end(), t);
    std::size_t k = it == start.begin() ? 0 : static_cast<std::size_t>(it - start.begin()) - 1;
    if (t > end[k] && k + 1 < start.size() && start[k + 1] - t < t - end[k]) ++k;
    return k;
  }
};

template <typename S>
BaseSubmaps<S> base_submaps(const HierarchyResult<S>& ha,
                            const std::vector<std::vector<ulc::Vec3<S>>>& frames_a,
                            const std::vector<double>& times_a, const SequenceExtrinsicOptions& o) {
  BaseSubmaps<S> out;
  if (ha.members.empty()) return out;
  const std::size_t layer = std::min<std::size_t>(
      static_cast<std::size_t>(std::max(o.target_layer, 0)), ha.members.size() - 1);
  const auto& members = ha.members[layer];
  out.planes.resize(members.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, members.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k != r.end(); ++k) {
                        const auto& m = members[k];
                        const auto& cloud = layer == 0 ? frames_a[m.begin] : m.cloud;
                        auto down = ulc::voxel_downsample(cloud, o.target_voxel);
                        out.planes[k] = Target<S>(down.ok() ? down.cloud.points : cloud, o.planes);
                      }
                    });
  for (const auto& m : members) {
    out.anchor.push_back(m.begin);
    out.start.push_back(times_a[m.begin]);
    out.end.push_back(times_a[m.end - 1]);
  }
  return out;
}

using Vec7 = Eigen::Matrix<double, 7, 1>;
using Mat7 = Eigen::Matrix<double, 7, 7>;
using Mat34 = Eigen::Matrix<double, 3, 4>;

/// What one pass over the matched points sums (7 parameters: [rho; phi; dt]).
struct JointSums {
  Mat7 H = Mat7::Zero();
  Vec7 g = Vec7::Zero();     ///< sum w J r
  std::vector<Vec7> term_g;  ///< g of each term (for time_sigma), filled by the caller
  double cost = 0.0;
  std::size_t count = 0, inliers = 0;
  double inlier_sq = 0.0;
  Vec3d sum_y = Vec3d::Zero();  ///< of the matched points C x, base frame (their centre)
  Mat3d sum_yyT = Mat3d::Zero();

  JointSums& operator+=(const JointSums& o) {
    H += o.H;
    g += o.g;
    sum_y += o.sum_y;
    sum_yyT += o.sum_yyT;
    cost += o.cost;
    count += o.count;
    inliers += o.inliers;
    inlier_sq += o.inlier_sq;
    return *this;
  }
  double rmse() const {
    return inliers ? std::sqrt(inlier_sq / static_cast<double>(inliers)) : 0.0;
  }
};

/// post(t) = T_world_anchor^-1 T_a(t) and its time derivative (central difference).
inline std::pair<Isometry3d, Mat34> placement(const std::vector<double>& times_a,
                                              const std::vector<Isometry3d>& world_a,
                                              const Isometry3d& anchor_inverse, double t,
                                              double h) {
  const Isometry3d post = anchor_inverse * time_sync_detail::pose_at(times_a, world_a, t);
  const Isometry3d plus = anchor_inverse * time_sync_detail::pose_at(times_a, world_a, t + h);
  const Isometry3d minus = anchor_inverse * time_sync_detail::pose_at(times_a, world_a, t - h);
  const Mat34 d = (plus.matrix() - minus.matrix()).topRows<3>() / (2.0 * h);
  return {post, d};
}

/// The point-to-plane residual of x and its Jacobian for C <- exp(xi) C and dt.
inline double joint_residual(const Vec3d& x, const Isometry3d& C, const Isometry3d& post,
                             const Mat34& dpost, const ulc::PlaneMatch& plane, Vec7& J) {
  const Vec3d y = C * x;
  const Vec3d u = post.linear().transpose() * plane.normal;
  J.head<3>() = u;
  J.segment<3>(3) = y.cross(u);
  J(6) = plane.normal.dot(dpost.leftCols<3>() * y + dpost.col(3));
  return plane.normal.dot(post * y - plane.point);
}

/// Step for H d = -g in the Jacobi-scaled eigenbasis, directions below min_condition skipped
/// (the first n parameters only).
inline Vec7 truncated_step(const JointSums& s, int n, double min_condition) {
  Vec7 step = Vec7::Zero();
  const Eigen::MatrixXd H = s.H.topLeftCorner(n, n);
  Eigen::VectorXd scale = H.diagonal().cwiseMax(1e-30).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd Hs = scale.asDiagonal() * H * scale.asDiagonal();
  const Eigen::VectorXd gs = scale.asDiagonal() * s.g.head(n);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Hs);
  const double top = eig.eigenvalues().maxCoeff();
  Eigen::VectorXd ds = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    const double l = eig.eigenvalues()(i);
    if (!(l > min_condition * top)) continue;
    const Eigen::VectorXd v = eig.eigenvectors().col(i);
    ds -= v * (v.dot(gs) / l);
  }
  step.head(n) = scale.asDiagonal() * ds;
  return step;
}

/// Standard deviation of dt by the cluster-robust ("sandwich") covariance
/// H^-1 (sum_c g_c g_c^T) H^-1, g_c = sum of w J r over a cluster of consecutive target frames:
/// points of one frame, and frames close in time, share their errors (a mis-modelled wall, a
/// pose error), so the textbook sigma^2 H^-1 that treats every point as independent is
/// optimistic by an order of magnitude. Infinite when dt is not observable.
inline double time_sigma(const Mat7& H, const std::vector<Vec7>& term_gradients,
                         std::size_t cluster) {
  const Eigen::FullPivLU<Mat7> lu(H);
  if (!lu.isInvertible()) return std::numeric_limits<double>::infinity();
  const Mat7 Hinv = lu.inverse();
  Mat7 meat = Mat7::Zero();
  const std::size_t c = std::max<std::size_t>(cluster, 1);
  for (std::size_t begin = 0; begin < term_gradients.size(); begin += c) {
    Vec7 g = Vec7::Zero();
    for (std::size_t i = begin; i < std::min(begin + c, term_gradients.size()); ++i)
      g += term_gradients[i];
    meat.noalias() += g * g.transpose();
  }
  const double v = (Hinv * meat * Hinv.transpose())(6, 6);
  return v >= 0.0 && std::isfinite(v) ? std::sqrt(v) : std::numeric_limits<double>::infinity();
}

/// 1 / (H_77 (H^-1)_77): dt's information left after C is marginalised, over its own.
inline double time_observability(const Mat7& H) {
  const Eigen::FullPivLU<Mat7> lu(H);
  if (!lu.isInvertible() || !(H(6, 6) > 0.0)) return 0.0;
  const double v = lu.inverse()(6, 6) * H(6, 6);
  return v > 0.0 && std::isfinite(v) ? 1.0 / v : 0.0;
}

}  // namespace sequence_detail

}  // namespace hots
