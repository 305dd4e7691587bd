// Shared helpers of the TERRA tests: seeded random directions and rotations, and a tiny
// synthetic scene (a street between buildings) seen by a virtual spinning LiDAR.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "../support/test_units.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace terra_test {

constexpr double kPi = 3.14159265358979323846;
using ulc_test::kDeg;

inline std::vector<ulc::Vec3d> random_directions(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<ulc::Vec3d> out;
  out.reserve(n);
  while (out.size() < n) {
    const ulc::Vec3d v(g(rng), g(rng), g(rng));
    if (v.norm() > 1e-6) out.push_back(v.normalized());
  }
  return out;
}

/// An axis-aligned box, an obstacle the rays stop at.
struct Box {
  ulc::Vec3d lo, hi;
};

/// A crossroads in a small town: a street along x, 16 m wide, crossing one along y, blocks of
/// different heights and setbacks, a far tower and a far wall where the streets end, pillars and
/// parked vans. Asymmetric on purpose, with returns from 1 m to ~95 m so that d1 = 20 m keeps a
/// good share of the cells.
inline std::vector<Box> street_scene() {
  return {
      {{12, 10, -2}, {40, 45, 12}},     // block ahead-left, 12 m tall
      {{14, -45, -2}, {34, -9, 22}},    // block ahead-right, taller and closer to the street
      {{-50, 9, -2}, {-11, 40, 30}},    // tall block behind-left
      {{-38, -40, -2}, {-13, -12, 8}},  // low block behind-right
      {{52, 16, -2}, {70, 35, 45}},     // tower further ahead-left
      {{90, -60, -2}, {95, 60, 20}},    // wall closing the x street ahead
      {{-75, -60, -2}, {-72, 60, 10}},  // low wall closing it behind
      {{-8, 70, -2}, {8, 75, 16}},      // building closing the y street on the left
      {{-6, -68, -2}, {9, -64, 25}},    // and on the right
      {{6, -7.5, -2}, {7, -6.5, 6}},    // pillars and parked vans
      {{-9, 6, -2}, {-8, 7, 7}},        //
      {{22, -8, -2}, {27, -6, 0.5}},    //
      {{-27, 5, -2}, {-22, 7.5, 0.3}},  //
      {{3, 25, -2}, {5, 27, 3}},        //
  };
}

/// Distance along unit ray d from the origin to the box, or +inf.
inline double ray_box(const ulc::Vec3d& d, const Box& b) {
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(d[a]) < 1e-12) {
      if (0 < b.lo[a] || 0 > b.hi[a]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double ta = b.lo[a] / d[a], tb = b.hi[a] / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::numeric_limits<double>::infinity();
  }
  return t0;
}

/// A spinning LiDAR at `position` (scene frame), turned by R_scene_lidar, with `beams` beams
/// from -25 to +15 degrees and `columns` azimuth steps. Returns points in the LiDAR's frame.
/// The ground is z = -2 (the sensor sits 2 m above it at position 0), ranges capped at 120 m.
inline std::vector<ulc::Vec3d> scan(const ulc::Mat3d& R_scene_lidar,
                                    const ulc::Vec3d& position = ulc::Vec3d::Zero(),
                                    std::size_t beams = 32, std::size_t columns = 720) {
  const std::vector<Box> boxes = street_scene();
  std::vector<ulc::Vec3d> points;
  points.reserve(beams * columns);
  for (std::size_t b = 0; b < beams; ++b) {
    const double elevation =
        (-25.0 + 40.0 * static_cast<double>(b) / static_cast<double>(beams - 1)) * kDeg;
    for (std::size_t c = 0; c < columns; ++c) {
      const double azimuth = 2.0 * kPi *
                             (static_cast<double>(c) + 0.5 * static_cast<double>(b % 2)) /
                             static_cast<double>(columns);
      const ulc::Vec3d ray_lidar(std::cos(elevation) * std::cos(azimuth),
                                 std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      const ulc::Vec3d d = R_scene_lidar * ray_lidar;
      double t = std::numeric_limits<double>::infinity();
      if (d.z() < -1e-9) t = (-2.0 - position.z()) / d.z();
      for (Box box : boxes) {
        box.lo -= position;
        box.hi -= position;
        t = std::min(t, ray_box(d, box));
      }
      if (t < 120.0) points.push_back(t * ray_lidar);
    }
  }
  return points;
}

/// A narrow field of view at `position` looking along `axis_scene` (within half_fov_deg of it),
/// in the sensor's frame turned by R = R_base_target: the dense level scan's points in the cone,
/// p_target = R^T p_level.
inline std::vector<ulc::Vec3d> narrow_scan(const ulc::Mat3d& R, const ulc::Vec3d& position,
                                           const ulc::Vec3d& axis_scene, double half_fov_deg) {
  const ulc::Vec3d axis = axis_scene.normalized();
  std::vector<ulc::Vec3d> out;
  for (const ulc::Vec3d& p : scan(ulc::Mat3d::Identity(), position, 128, 2048))
    if (p.normalized().dot(axis) > std::cos(half_fov_deg * kDeg)) out.push_back(R.transpose() * p);
  return out;
}

}  // namespace terra_test
