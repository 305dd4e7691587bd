// A short simulated 64-32 drive shared by the HOTS tests, with the true poses in the map
// frames odometry would use, and odometry-like drifting copies of them.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "../jeep/jeep_test_util.hpp"
#include "hots_test_util.hpp"

namespace hots_drive {

struct Drive {
  ulc::sim::Dataset data;
  std::vector<ulc::Isometry3d> truth_a, truth_b;  ///< in the map frames odometry would use
};

inline const Drive& drive() {
  static const Drive d = [] {
    Drive out;
    jeep_test::DriveSpec spec;
    spec.scenario = "64-32";
    spec.seconds = 3.0;
    spec.seed = 3;
    spec.decimation = 4;
    out.data = jeep_test::simulate(spec);
    const auto& a = out.data.lidars[0];
    const auto& b = out.data.lidars[1];
    const double t0 = a.timestamps.front();
    // Map a: a's frame at its first timestamp; map b: b's frame at that instant.
    const ulc::Isometry3d origin_a = jeep_test::lidar_pose(out.data, 0, t0).inverse();
    const ulc::Isometry3d origin_b = jeep_test::lidar_pose(out.data, 1, t0).inverse();
    for (double t : a.timestamps)
      out.truth_a.push_back(origin_a * jeep_test::lidar_pose(out.data, 0, t));
    for (double t : b.timestamps)
      out.truth_b.push_back(origin_b * jeep_test::lidar_pose(out.data, 1, t));
    return out;
  }();
  return d;
}

/// Odometry-like errors: a slow drift (growing with time) plus a little white noise, in each
/// sensor's own frame.
inline std::vector<ulc::Isometry3d> drifting(const std::vector<ulc::Isometry3d>& truth,
                                             const std::vector<double>& times, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  ulc::Vec6d rate;
  rate << 0.01, -0.005, 0.003, 0.03 * hots_test::kDeg, -0.02 * hots_test::kDeg,
      0.05 * hots_test::kDeg;
  auto out = truth;
  for (std::size_t k = 1; k < out.size(); ++k) {
    const ulc::Vec6d xi = (times[k] - times[0]) * rate +
                          hots_test::random_vector6(rng, 0.002, 0.01 * hots_test::kDeg);
    out[k] = out[k] * ulc::se3_exp(xi);
  }
  return out;
}

}  // namespace hots_drive
