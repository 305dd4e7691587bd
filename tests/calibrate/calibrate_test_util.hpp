// Helpers of the pipeline tests: a short simulated 64-32 drive held in memory (decimated so the
// tests stay fast), the paper's disturbance of a ground truth, and exact bit comparison.
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "../support/test_units.hpp"
#include "pipeline/calibrate.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/types.hpp"
#include "ulc/sim/simulate.hpp"

namespace calibrate_test {
/// The simulator's frames, the type most of these tests calibrate.
using SimFrames = std::vector<ulc::PointCloud<float>>;
}  // namespace calibrate_test

// The whole pipeline on the simulator's frames is compiled once, in calibrate_instantiation.cpp:
// instantiated in every test file, it made each one take about 3 minutes to compile.
extern template ulc::PairCalibration
ulc::calibrate_pair<calibrate_test::SimFrames, calibrate_test::SimFrames>(
    const calibrate_test::SimFrames&, const std::vector<double>&, const calibrate_test::SimFrames&,
    const std::vector<double>&, const ulc::CalibrateOptions&);

namespace calibrate_test {

using ulc_test::kDeg;

/// A seeded 64-32 town drive, every `decimation`-th point kept.
inline ulc::sim::Dataset simulate_64_32(double seconds, std::uint64_t seed, unsigned decimation) {
  ulc::sim::SimulationOptions o;
  o.seconds = seconds;
  o.seed = seed;
  o.decimation = decimation;
  return ulc::sim::simulate(*ulc::sim::scenario("64-32"), o).dataset;
}

/// The faces of the axis-aligned box from lo to hi on a `step` grid; only the pairs of faces
/// across the axes in `axes` (a corridor along x leaves out its ends: {1, 2}).
inline std::vector<Eigen::Vector3d> box_faces(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                              double step,
                                              const std::vector<int>& axes = {0, 1, 2}) {
  std::vector<Eigen::Vector3d> points;
  for (const int axis : axes)
    for (const double side : {lo[axis], hi[axis]}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (double a = lo[u]; a <= hi[u]; a += step)
        for (double b = lo[v]; b <= hi[v]; b += step) {
          Eigen::Vector3d p;
          p[axis] = side;
          p[u] = a;
          p[v] = b;
          points.push_back(p);
        }
    }
  return points;
}

/// The simulated pair whose target is `target`, or nullptr.
inline const ulc::sim::PairTruth* pair_with_target(const ulc::sim::Dataset& d,
                                                   const std::string& target) {
  for (const auto& p : d.pairs)
    if (p.target == target) return &p;
  return nullptr;
}

/// One frame of each LiDAR of `scenario`, parked 5 s into its route: a static snapshot.
inline ulc::sim::Dataset parked_snapshot(const std::string& scenario, std::uint64_t seed) {
  ulc::sim::SimulationOptions o;
  o.seconds = 0.1;
  o.seed = seed;
  o.static_at_s = 5.0;
  return ulc::sim::simulate(*ulc::sim::scenario(scenario), o).dataset;
}

/// Six frames of each LiDAR of the 64-32 rig, the first 0.6 s of the town drive.
inline const ulc::sim::Dataset& drive_64_32() {
  static const ulc::sim::Dataset d = simulate_64_32(0.6, 1, 2);
  return d;
}

/// Three seconds (30 frames of each LiDAR) of the same drive, decimated 4x: enough windows for
/// HOTS's hierarchy while the test stays short.
inline const ulc::sim::Dataset& drive_64_32_hots() {
  static const ulc::sim::Dataset d = simulate_64_32(3.0, 3, 4);
  return d;
}

/// The same frames as std::vector<Eigen::Vector3d> (double, no per-point times).
inline std::vector<std::vector<Eigen::Vector3d>> as_vectors(
    const std::vector<ulc::PointCloud<float>>& frames) {
  std::vector<std::vector<Eigen::Vector3d>> out;
  for (const auto& f : frames) {
    out.emplace_back();
    for (const auto& p : f.points) out.back().push_back(p.cast<double>());
  }
  return out;
}

/// The same frames as ulc::PointCloud<double>, per-point times kept.
inline std::vector<ulc::PointCloud<double>> as_double_clouds(
    const std::vector<ulc::PointCloud<float>>& frames) {
  std::vector<ulc::PointCloud<double>> out(frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    for (const auto& p : frames[k].points) out[k].points.push_back(p.cast<double>());
    out[k].times = frames[k].times;
  }
  return out;
}

/// The paper's disturbance: `angle` about a random axis, `distance` in a random direction.
inline ulc::Isometry3d disturbed(const ulc::Isometry3d& truth, std::uint64_t seed, double angle_rad,
                                 double distance_m) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const ulc::Vec3d axis = ulc::Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  const ulc::Vec3d dir = ulc::Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  ulc::Isometry3d out = truth;
  out.linear() = truth.linear() * ulc::so3_exp(ulc::Vec3d(angle_rad * axis));
  out.translation() = truth.translation() + distance_m * dir;
  return out;
}

/// A progress callback that records each stage name once, in the order the stages report.
inline ulc::CalibrateProgress record_stages(std::vector<std::string>& seen) {
  return [&seen](const std::string& stage, double) {
    if (seen.empty() || seen.back() != stage) seen.push_back(stage);
  };
}

inline bool same_bits(const ulc::Isometry3d& a, const ulc::Isometry3d& b) {
  return std::memcmp(a.matrix().data(), b.matrix().data(), 16 * sizeof(double)) == 0;
}

}  // namespace calibrate_test
