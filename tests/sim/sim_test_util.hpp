// Helpers shared by the simulator tests: point-to-plane residuals against a reference cloud,
// deskewing with a trajectory, medians and the point-to-plane Hessian.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

#include "ulc/core/kdtree.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/normals.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/sim/simulate.hpp"

namespace sim_test {

using ulc::Isometry3d;
using ulc::Mat3d;
using ulc::Vec3d;

inline double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}
inline double median(const std::vector<double>& v) {
  return quantile(v, 0.5);
}

/// A reference cloud with PCA normals (k nearest, default 10) and a kd-tree, for point-to-plane
/// residuals.
class PlaneReference {
 public:
  PlaneReference(ulc::PointCloud<double> cloud, const Vec3d& viewpoint, std::size_t k = 10)
      : cloud_(std::move(cloud)), tree_(cloud_) {
    ulc::NormalEstimationOptions o;
    o.viewpoint = viewpoint;
    o.k = k;
    normals_ = ulc::estimate_normals(cloud_, tree_, o);
  }

  /// |n . (q - p)| for each query whose nearest reference point is within max_gap and lies on
  /// a planar patch (planarity above min_planarity). Optional filter on the normal.
  template <class Filter>
  std::vector<double> residuals(const std::vector<Vec3d>& queries, double max_gap,
                                double min_planarity, Filter&& keep_normal) const {
    std::vector<double> out;
    for (const Vec3d& q : queries) {
      std::size_t j;
      double d2;
      if (!tree_.nearest(q, j, d2) || d2 > max_gap * max_gap) continue;
      const auto& n = normals_.points[j];
      if (!n.valid || n.planarity < min_planarity || !keep_normal(n.normal)) continue;
      out.push_back(std::abs(n.normal.dot(q - cloud_.points[j])));
    }
    return out;
  }
  std::vector<double> residuals(const std::vector<Vec3d>& queries, double max_gap,
                                double min_planarity) const {
    return residuals(queries, max_gap, min_planarity, [](const Vec3d&) { return true; });
  }

  const ulc::PointCloud<double>& cloud() const { return cloud_; }
  const ulc::NormalsResult<double>& normals() const { return normals_; }

 private:
  ulc::PointCloud<double> cloud_;
  ulc::KdTree<ulc::PointCloud<double>> tree_;
  ulc::NormalsResult<double> normals_;
};

/// T_world_vehicle at t from a sampled trajectory (slerp between the bracketing samples).
inline Isometry3d sampled_pose(const std::vector<ulc::sim::TrajectorySample>& traj, double t) {
  const double dt = traj[1].t - traj[0].t;
  const auto k = static_cast<std::size_t>(
      std::clamp(std::floor((t - traj[0].t) / dt), 0.0, static_cast<double>(traj.size() - 2)));
  auto iso = [](const ulc::sim::TrajectorySample& s) {
    Isometry3d T = Isometry3d::Identity();
    T.linear() = s.orientation.toRotationMatrix();
    T.translation() = s.position;
    return T;
  };
  return ulc::interpolate(iso(traj[k]), iso(traj[k + 1]), (t - traj[k].t) / dt);
}

/// Points of a frame moved into the world: each with the pose of its own instant.
/// `t0_true` is the frame timestamp converted to true time; T_vehicle_lidar the mount.
inline std::vector<Vec3d> deskew(const ulc::PointCloud<float>& cloud, double t0_true,
                                 const Isometry3d& T_vehicle_lidar,
                                 const std::vector<ulc::sim::TrajectorySample>& traj,
                                 double min_range = 0.0, double max_range = 1e9) {
  std::vector<Vec3d> out;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3d p = cloud.points[i].cast<double>();
    if (p.norm() < min_range || p.norm() > max_range) continue;
    out.push_back(sampled_pose(traj, t0_true + cloud.times[i]) * (T_vehicle_lidar * p));
  }
  return out;
}

/// Sum over points with good normals of J^T J, J = [n^T, ((p - c) x n)^T / L]: the Gauss-Newton
/// Hessian of point-to-plane alignment of a scan against itself, with the rotational part
/// scaled by the RMS distance L of the points from c so both blocks have units of metres.
inline Eigen::Matrix<double, 6, 6> plane_hessian(const PlaneReference& ref, const Vec3d& c,
                                                 double min_planarity) {
  const auto& pts = ref.cloud().points;
  double l2 = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto& pn = ref.normals().points[i];
    if (!pn.valid || pn.planarity < min_planarity) continue;
    l2 += (pts[i] - c).squaredNorm();
    ++n;
  }
  const double L = std::sqrt(l2 / std::max<std::size_t>(n, 1));
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto& pn = ref.normals().points[i];
    if (!pn.valid || pn.planarity < min_planarity) continue;
    Eigen::Matrix<double, 6, 1> J;
    J.head<3>() = pn.normal;
    J.tail<3>() = (pts[i] - c).cross(pn.normal) / L;
    H += J * J.transpose();
  }
  return H;
}

inline ulc::PointCloud<double> to_double(const std::vector<Vec3d>& pts) {
  ulc::PointCloud<double> c;
  c.points = pts;
  return c;
}

}  // namespace sim_test
