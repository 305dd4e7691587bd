// Helpers of the registration tests: synthetic plane scenes, random transforms, static
// simulated frames (cached per process) and bit comparisons.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "../support/test_units.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/types.hpp"
#include "ulc/sim/simulate.hpp"

namespace reg_test {

using ulc::Isometry3d;
using ulc::Mat3d;
using ulc::Vec3d;
using ulc::Vec6d;

using ulc_test::kDeg;

/// Points sampled uniformly on a rectangle: origin + a*u + b*v, a in [0, lu], b in [0, lv].
inline void sample_rectangle(std::vector<Vec3d>& out, std::mt19937_64& rng, const Vec3d& origin,
                             const Vec3d& u, const Vec3d& v, double lu, double lv, std::size_t n,
                             double noise) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Vec3d normal = u.cross(v).normalized();
  for (std::size_t i = 0; i < n; ++i)
    out.push_back(origin + unit(rng) * lu * u + unit(rng) * lv * v + noise * gauss(rng) * normal);
}

/// A courtyard: ground, four walls of different sizes and two boxes, so that every direction
/// is constrained. About 6 * n_per_face points around the origin, within ~15 m.
inline std::vector<Vec3d> courtyard(std::uint64_t seed, std::size_t n_per_face, double noise) {
  std::mt19937_64 rng(seed);
  std::vector<Vec3d> p;
  const Vec3d ex(1, 0, 0), ey(0, 1, 0), ez(0, 0, 1);
  sample_rectangle(p, rng, Vec3d(-15, -12, 0), ex, ey, 30, 24, 2 * n_per_face, noise);  // ground
  sample_rectangle(p, rng, Vec3d(-15, 12, 0), ex, ez, 30, 6, n_per_face, noise);        // north
  sample_rectangle(p, rng, Vec3d(-15, -12, 0), ex, ez, 22, 4, n_per_face, noise);       // south
  sample_rectangle(p, rng, Vec3d(15, -12, 0), ey, ez, 24, 5, n_per_face, noise);        // east
  sample_rectangle(p, rng, Vec3d(-15, -5, 0), ey, ez, 12, 3, n_per_face / 2, noise);    // west
  const Vec3d d1 = Vec3d(1, 1, 0).normalized(), d2 = Vec3d(-1, 1, 0).normalized();
  sample_rectangle(p, rng, Vec3d(4, 2, 0), d1, ez, 3, 2, n_per_face / 3, noise);  // slanted box
  sample_rectangle(p, rng, Vec3d(4, 2, 0), d2, ez, 2, 2, n_per_face / 3, noise);
  sample_rectangle(p, rng, Vec3d(-6, -4, 1.5), ex, ey, 2, 2, n_per_face / 3, noise);  // table top
  return p;
}

/// A rigid transform with the given rotation angle and translation length, random directions.
inline Isometry3d random_transform(std::mt19937_64& rng, double angle_rad, double distance_m) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Vec3d axis = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  const Vec3d dir = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  Isometry3d T = Isometry3d::Identity();
  T.linear() = ulc::so3_exp(Vec3d(angle_rad * axis));
  T.translation() = distance_m * dir;
  return T;
}

inline std::vector<Vec3d> transformed(const std::vector<Vec3d>& p, const Isometry3d& T) {
  std::vector<Vec3d> out;
  out.reserve(p.size());
  for (const Vec3d& x : p) out.push_back(T * x);
  return out;
}

template <typename S>
ulc::PointCloud<S> to_cloud(const std::vector<Vec3d>& p) {
  ulc::PointCloud<S> c;
  for (const Vec3d& x : p) c.points.push_back(x.cast<S>());
  return c;
}

/// Two frames of each LiDAR of the 64-32 rig, the vehicle parked (no motion distortion),
/// columns decimated by 2; simulated once per process.
struct StaticFrames {
  ulc::sim::Dataset dataset;
  const ulc::PointCloud<float>& frame(std::size_t lidar, std::size_t k) const {
    return dataset.lidars[lidar].frames[k];
  }
  Isometry3d T_base_target() const { return dataset.pairs[0].T_base_target; }
};

inline const StaticFrames& static_frames() {
  static const StaticFrames frames = [] {
    ulc::sim::SimulationOptions o;
    o.seconds = 0.2;
    o.seed = 3;
    o.static_at_s = 6.0;
    o.decimation = 2;
    StaticFrames f;
    f.dataset = ulc::sim::simulate(*ulc::sim::scenario("64-32"), o).dataset;
    return f;
  }();
  return frames;
}

template <typename T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

inline bool same_bits(const Isometry3d& a, const Isometry3d& b) {
  return std::memcmp(a.matrix().data(), b.matrix().data(), 16 * sizeof(double)) == 0;
}

}  // namespace reg_test
