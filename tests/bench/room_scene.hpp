// The synthetic scene of the refinement baselines' tests (bench/gicp_baseline.hpp,
// bench/ndt_baseline.hpp): two independent samplings of the same room (floor, ceiling, four
// walls) and a slanted panel, the second placed in the source frame by a known pose, both
// prepared as bench_jeep prepares frames (odometry::prepare_scan, 0.25 m voxels; no range gate,
// the room being around the origin).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <vector>

#include "odometry/scan_preparation.hpp"
#include "test_units.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/types.hpp"

namespace room_scene {

using ulc::Isometry3d;
using ulc::Vec3d;
using Points = std::vector<Vec3d>;

/// A uniform number in [-1, 1) from the raw generator (the same on every standard library).
inline double jitter(std::mt19937& rng) {
  return static_cast<double>(rng() % 2000000) / 1e6 - 1.0;
}

/// Points on the rectangle origin + u * [0, |eu|] + v * [0, |ev|] every `step` metres, each
/// moved within the rectangle by up to 40 % of a step.
inline void sample_rectangle(const Vec3d& origin, const Vec3d& eu, const Vec3d& ev, double step,
                             std::mt19937& rng, std::vector<Vec3d>& out) {
  const int nu = static_cast<int>(eu.norm() / step), nv = static_cast<int>(ev.norm() / step);
  const Vec3d u = eu.normalized(), v = ev.normalized();
  for (int i = 0; i <= nu; ++i)
    for (int j = 0; j <= nv; ++j) {
      const double du = i + 0.4 * jitter(rng);  // two statements: a fixed order of draws
      const double dv = j + 0.4 * jitter(rng);
      out.push_back(origin + du * step * u + dv * step * v);
    }
}

/// A 10 x 8 x 3 m room around the origin and a panel leaning in a corner, sampled every 10 cm.
inline ulc::PointCloud<double> room(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Vec3d> p;
  const double h = 0.1;
  sample_rectangle({-5, -4, 0}, {10, 0, 0}, {0, 8, 0}, h, rng, p);       // floor
  sample_rectangle({-5, -4, 3}, {10, 0, 0}, {0, 8, 0}, h, rng, p);       // ceiling
  sample_rectangle({-5, -4, 0}, {10, 0, 0}, {0, 0, 3}, h, rng, p);       // wall y = -4
  sample_rectangle({-5, 4, 0}, {10, 0, 0}, {0, 0, 3}, h, rng, p);        // wall y = 4
  sample_rectangle({-5, -4, 0}, {0, 8, 0}, {0, 0, 3}, h, rng, p);        // wall x = -5
  sample_rectangle({5, -4, 0}, {0, 8, 0}, {0, 0, 3}, h, rng, p);         // wall x = 5
  sample_rectangle({2, 2, 0}, {1.5, 1.0, 0}, {0.5, 0.5, 2}, h, rng, p);  // slanted panel
  ulc::PointCloud<double> cloud;
  cloud.points.assign(p.begin(), p.end());
  return cloud;
}

inline ulc::PointCloud<double> moved(const ulc::PointCloud<double>& c, const Isometry3d& T) {
  ulc::PointCloud<double> out;
  for (const auto& p : c.points) out.points.push_back(T * p);
  return out;
}

/// A rotation of `deg` degrees about `axis`, then the translation t.
inline Isometry3d pose(double deg, const Vec3d& axis, const Vec3d& t) {
  Isometry3d T = Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(deg * ulc_test::kDeg, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

/// A cloud through the library's preparation: 0.25 m voxel centroids, no range gate, no deskew.
inline Points prepared(const ulc::PointCloud<double>& cloud) {
  odometry::ScanOptions o;
  o.min_range = 0.0;
  o.max_range = 1e9;
  o.map_voxel = 0.25;
  o.deskew = false;
  return odometry::prepare_scan<double>(cloud, ulc::Vec6d::Zero(), 0.0, o).dense;
}

/// The target room, and a second sampling of it in the source frame: T_target_source = truth.
struct Scene {
  Isometry3d truth = pose(4.0, {1, 2, 3}, {0.3, -0.2, 0.1});
  Points target = prepared(room(1));
  Points source = prepared(moved(room(2), truth.inverse()));
};

}  // namespace room_scene
