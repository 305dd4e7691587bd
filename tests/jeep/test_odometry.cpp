// Odometry (the pose phase run along a drive): single- and multi-LiDAR poses against the
// simulator's trajectory, the base's odometry carried to the target through the mount, poses
// for unpaired frames, the same bits on 1 and 2 threads.
#include <tbb/task_arena.h>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <vector>

#include "../registration/registration_test_util.hpp"
#include "jeep_test_util.hpp"
#include "odometry/run_odometry.hpp"
#include "ulc/core/pose_error.hpp"

using namespace jeep_test;

namespace {

/// One second of the 64-32 rig driving through town, columns decimated by 4.
const ulc::sim::Dataset& odometry_drive() {
  static const ulc::sim::Dataset d = [] {
    DriveSpec spec;
    spec.scenario = "64-32";
    spec.seconds = 1.0;
    spec.seed = 2;
    spec.decimation = 4;
    return simulate(spec);
  }();
  return d;
}

/// Largest error of the estimated poses against T_first^-1 T_k of the ground truth.
ulc::PoseError worst_relative_error(const std::vector<Isometry3d>& estimated,
                                    const std::vector<Isometry3d>& truth_world,
                                    const Isometry3d& origin_world) {
  ulc::PoseError worst;
  for (std::size_t k = 0; k < estimated.size(); ++k) {
    const auto e =
        ulc::pose_error(Isometry3d(origin_world.inverse() * truth_world[k]), estimated[k]);
    worst.rotation_deg = std::max(worst.rotation_deg, e.rotation_deg);
    worst.translation_m = std::max(worst.translation_m, e.translation_m);
  }
  return worst;
}

std::vector<Isometry3d> truth_of(const ulc::sim::Dataset& d, std::size_t lidar,
                                 const std::vector<double>& stamps) {
  std::vector<Isometry3d> out;
  for (double t : stamps) out.push_back(lidar_pose(d, lidar, t));
  return out;
}

}  // namespace

TEST_CASE("single-LiDAR odometry follows the simulated drive", "[jeep][odometry]") {
  const auto& d = odometry_drive();
  const auto& a = d.lidars[0];
  REQUIRE(a.frames.size() >= 8);
  const auto r = odometry::run_single_odometry(a.frames, a.timestamps);
  INFO(odometry::to_string(r.status) << ": " << r.reason);
  REQUIRE(r.ok());
  REQUIRE(r.poses_a.size() == a.frames.size());
  CHECK(r.poses_a[0].isApprox(Isometry3d::Identity(), 1e-12));
  const auto truth = truth_of(d, 0, a.timestamps);
  const auto e = worst_relative_error(r.poses_a, truth, truth[0]);
  INFO("worst e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m over "
                      << (truth.back().translation() - truth[0].translation()).norm() << " m");
  CHECK(e.rotation_deg < 0.1);
  CHECK(e.translation_m < 0.03);
}

TEST_CASE("multi-LiDAR odometry gives both LiDARs' poses in their own map frames",
          "[jeep][odometry]") {
  const auto& d = odometry_drive();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  const Isometry3d C = d.pairs[0].T_base_target;
  const auto r = odometry::run_odometry(a.frames, a.timestamps, b.frames, b.timestamps, C);
  INFO(odometry::to_string(r.status) << ": " << r.reason);
  REQUIRE(r.ok());
  REQUIRE(r.pairs.size() == a.frames.size());
  // Map a: a's frame at its first timestamp; map b: b's frame at that same instant.
  const Isometry3d origin_a = lidar_pose(d, 0, a.timestamps[0]);
  const auto ea = worst_relative_error(r.poses_a, truth_of(d, 0, a.timestamps), origin_a);
  const auto eb =
      worst_relative_error(r.poses_b, truth_of(d, 1, b.timestamps), Isometry3d(origin_a * C));
  INFO("a: " << ea.rotation_deg << " deg, " << ea.translation_m << " m; b: " << eb.rotation_deg
             << " deg, " << eb.translation_m << " m");
  // Worst frame of a 1 s drive with a quarter of the columns: 0.1005 deg with the default
  // coarse-then-fine steps (the fine stage alone stayed just under 0.1).
  CHECK(ea.rotation_deg < 0.15);
  CHECK(ea.translation_m < 0.03);
  CHECK(eb.rotation_deg < 0.15);
  CHECK(eb.translation_m < 0.03);
  // The rigid mount holds between every pair of poses: P_b = C^-1 P_a(t_b) C.
  for (std::size_t k = 0; k < r.steps.size(); ++k) {
    const auto& s = r.steps[k];
    const Isometry3d Pa_tb = s.pose_a * ulc::se3_exp(Vec6d((s.t_b - s.t_a) * s.twist));
    CHECK(s.pose_b.isApprox(Isometry3d(C.inverse() * Pa_tb * C), 1e-9));
  }
}

TEST_CASE("the base's own odometry carried through the mount gives the target's poses",
          "[jeep][odometry]") {
  const auto& d = odometry_drive();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  const Isometry3d C = d.pairs[0].T_base_target;
  const auto single = odometry::run_single_odometry(a.frames, a.timestamps);
  REQUIRE(single.ok());
  const auto r = odometry::with_target_poses(single, b.timestamps, C);
  REQUIRE(r.ok());
  REQUIRE(r.poses_b.size() == b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i)
    CHECK(reg_test::same_bits(r.poses_a[i], single.poses_a[i]));  // a's own poses are kept
  // b's poses against the truth, in map b (b's frame at a's first instant), within the joint
  // odometry's bounds above.
  const Isometry3d origin_a = lidar_pose(d, 0, a.timestamps[0]);
  const auto eb =
      worst_relative_error(r.poses_b, truth_of(d, 1, b.timestamps), Isometry3d(origin_a * C));
  INFO("b: " << eb.rotation_deg << " deg, " << eb.translation_m << " m");
  CHECK(eb.rotation_deg < 0.15);
  CHECK(eb.translation_m < 0.03);
  // The rigid mount at b's instants: P_b = C^-1 P_a(t_b) C, a's pose carried by its twist.
  for (std::size_t j = 0; j < b.frames.size(); ++j) {
    const double t = b.timestamps[j];
    const auto& s = *std::min_element(
        single.steps.begin(), single.steps.end(),
        [t](const auto& x, const auto& y) { return std::abs(x.t_a - t) < std::abs(y.t_a - t); });
    const Isometry3d Pa_tb = s.pose_a * ulc::se3_exp(Vec6d((t - s.t_a) * s.twist));
    CHECK(r.poses_b[j].isApprox(Isometry3d(C.inverse() * Pa_tb * C), 1e-9));
  }
  // A clock offset moves b's instants on a's clock: the pose of t_b + offset.
  const auto shifted = odometry::with_target_poses(single, b.timestamps, C, 0.05);
  const auto later = odometry::with_target_poses(
      single,
      [&] {
        auto t = b.timestamps;
        for (double& x : t) x += 0.05;
        return t;
      }(),
      C);
  for (std::size_t j = 0; j < b.frames.size(); ++j)
    CHECK(reg_test::same_bits(shifted.poses_b[j], later.poses_b[j]));
}

TEST_CASE("odometry poses unpaired frames by extrapolating the nearest pair", "[jeep][odometry]") {
  const auto& d = odometry_drive();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  // b loses frames 3 and 4: a's frames 3 and 4 have no partner.
  std::vector<ulc::PointCloud<float>> frames_b;
  std::vector<double> times_b;
  for (std::size_t k = 0; k < b.frames.size(); ++k) {
    if (k == 3 || k == 4) continue;
    frames_b.push_back(b.frames[k]);
    times_b.push_back(b.timestamps[k]);
  }
  const Isometry3d C = d.pairs[0].T_base_target;
  const auto r = odometry::run_odometry(a.frames, a.timestamps, frames_b, times_b, C);
  REQUIRE(r.ok());
  CHECK(r.pairs.size() == a.frames.size() - 2);
  REQUIRE(r.poses_a.size() == a.frames.size());
  REQUIRE(r.poses_b.size() == frames_b.size());
  CHECK_FALSE(r.estimated_a[3]);
  CHECK_FALSE(r.estimated_a[4]);
  CHECK(r.estimated_a[5]);
  for (bool e : r.estimated_b) CHECK(e);
  const auto truth = truth_of(d, 0, a.timestamps);
  const auto e = worst_relative_error(r.poses_a, truth, truth[0]);
  CHECK(e.translation_m < 0.05);
  CHECK(e.rotation_deg < 0.15);
}

TEST_CASE("odometry recovers from a prediction 40 cm off along the road", "[jeep][odometry]") {
  // A braking or accelerating vehicle leaves the constant-velocity prediction decimetres off;
  // the default steps (coarse, then fine) must pull it back, or the odometry runs away.
  const auto& a = odometry_drive().lidars[0];
  REQUIRE(a.frames.size() >= 6);
  const odometry::OdometryOptions options;
  const double period = a.timestamps[1] - a.timestamps[0];
  // Frames 0..4 as run_odometry steps them; the last step gives the reference pose.
  auto run = [&](const std::optional<Isometry3d>& last_guess) {
    odometry::Odometry<float> odometry(options);
    odometry::OdometryStep last;
    for (std::size_t k = 0; k < 5; ++k) {
      const auto scan =
          odometry::prepare_scan<float>(a.frames[k], odometry.twist(), period, options.scan);
      last = odometry.step(scan, a.timestamps[k], nullptr, a.timestamps[k],
                           k == 4 ? last_guess : std::nullopt);
    }
    return last;
  };
  const auto reference = run(std::nullopt);
  REQUIRE(reference.registered);
  Isometry3d off = reference.scan_pose_a;
  off.translate(Vec3d(0.4, 0.0, 0.0));  // 40 cm along the body's forward axis
  const auto recovered = run(off);
  REQUIRE(recovered.registered);
  const auto e = ulc::pose_error(reference.scan_pose_a, recovered.scan_pose_a);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m");
  CHECK(e.translation_m < 0.02);
  CHECK(e.rotation_deg < 0.05);
}

TEST_CASE("odometry gives the same bits on 1 and 2 threads", "[jeep][odometry][threads]") {
  const auto& d = odometry_drive();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  const Isometry3d C = d.pairs[0].T_base_target;
  auto run = [&] {
    return odometry::run_odometry(a.frames, a.timestamps, b.frames, b.timestamps, C).poses_b;
  };
  tbb::task_arena one(1), two(2);
  const auto p1 = one.execute(run);
  const auto p2 = two.execute(run);
  REQUIRE(p1.size() == p2.size());
  for (std::size_t k = 0; k < p1.size(); ++k)
    CHECK(std::memcmp(p1[k].matrix().data(), p2[k].matrix().data(), 16 * sizeof(double)) == 0);
}

TEST_CASE("odometry refuses unusable input", "[jeep][odometry]") {
  const auto& a = odometry_drive().lidars[0];
  std::vector<double> bad = a.timestamps;
  bad[2] = bad[1] - 1.0;
  CHECK(odometry::run_single_odometry(a.frames, bad).status ==
        odometry::OdometryStatus::invalid_input);
  std::vector<double> short_times(a.timestamps.begin(), a.timestamps.end() - 1);
  CHECK(odometry::run_single_odometry(a.frames, short_times).status ==
        odometry::OdometryStatus::invalid_input);
  odometry::OdometryOptions o;
  o.scan.map_voxel = -1;
  CHECK(odometry::run_single_odometry(a.frames, a.timestamps, o).status ==
        odometry::OdometryStatus::invalid_input);
  const std::vector<ulc::PointCloud<float>> none;
  CHECK(odometry::run_single_odometry(none, {}).status == odometry::OdometryStatus::no_pairs);
}
