// Point-to-plane registration: recovers known transforms (synthetic planes, simulated scans,
// float and double clouds), reports degenerate, starved and invalid problems, and gives the
// same bits on 1 and 2 threads.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "registration_test_util.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/registration_target.hpp"
#include "ulc/core/voxel_downsample.hpp"

using namespace reg_test;
using ulc::RegistrationStatus;

TEMPLATE_TEST_CASE("registration recovers a known transform on a synthetic courtyard",
                   "[registration]", float, double) {
  using S = TestType;
  const auto target_points = courtyard(1, 1500, 0.01);
  const auto scene_again = courtyard(2, 1500, 0.01);  // other samples of the same surfaces
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 3; ++trial) {
    const Isometry3d T_true = random_transform(rng, 4.0 * kDeg, 0.6);
    // The source sees the scene from T_true's other side: T_true maps it back onto the target.
    const auto source = to_cloud<S>(transformed(scene_again, T_true.inverse()));
    const ulc::PlaneCloud<S> target(to_cloud<S>(target_points));
    ulc::RegistrationOptions o;
    o.max_correspondence_distance = 2.0;
    const auto r = ulc::register_point_to_plane(source, target, ulc::Isometry3<S>::Identity(), o);
    INFO("trial " << trial << ": " << ulc::to_string(r.status) << " after " << r.iterations);
    REQUIRE(r.ok());
    const auto e = ulc::pose_error(T_true, Isometry3d(r.pose.template cast<double>()));
    CHECK(e.rotation_deg < 0.01);
    CHECK(e.translation_m < 0.002);
    CHECK(r.inlier_ratio() > 0.95);
    CHECK(r.rmse < 0.03);  // noise 1 cm on both sides
    CHECK(r.condition > 1e-2);
  }
}

TEMPLATE_TEST_CASE(
    "registration recovers a known transform of a simulated scan within 0.05 deg "
    "and 1 cm",
    "[registration][sim]", float, double) {
  using S = TestType;
  const auto& frames = static_frames();
  // Two sweeps of the parked HDL-64E: same scene, independent noise and sampling.
  auto as_s = [](const ulc::PointCloud<float>& f) {
    ulc::PointCloud<S> c;
    for (const auto& p : f.points) c.points.push_back(p.cast<S>());
    return c;
  };
  const auto target_cloud = ulc::voxel_downsample(as_s(frames.frame(0, 0)), 0.2).cloud;
  const auto moved = ulc::voxel_downsample(as_s(frames.frame(0, 1)), 0.4).cloud;
  const ulc::PlaneCloud<S> target(target_cloud);
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 3; ++trial) {
    const Isometry3d T_true = random_transform(rng, 3.0 * kDeg, 0.5);
    ulc::PointCloud<S> source;
    const Isometry3d T_inv = T_true.inverse();
    for (const auto& p : moved.points)
      source.points.push_back((T_inv * p.template cast<double>()).template cast<S>());
    ulc::RegistrationOptions o;
    o.max_correspondence_distance = 1.5;
    const auto r = ulc::register_point_to_plane(source, target, ulc::Isometry3<S>::Identity(), o);
    INFO("trial " << trial << ": " << ulc::to_string(r.status) << " after " << r.iterations
                  << " iterations, inliers " << r.inliers << " / " << r.source_points);
    REQUIRE(r.ok());
    const auto e = ulc::pose_error(T_true, Isometry3d(r.pose.template cast<double>()));
    INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m");
    CHECK(e.rotation_deg < 0.05);
    CHECK(e.translation_m < 0.01);
  }
}

TEST_CASE("scan to scan across two sensors of a parked rig finds the mounting",
          "[registration][sim]") {
  const auto& frames = static_frames();
  const auto target_cloud = ulc::voxel_downsample(frames.frame(0, 0), 0.2).cloud;  // HDL-64E
  const auto source = ulc::voxel_downsample(frames.frame(1, 0), 0.3).cloud;        // VLP-32C
  const ulc::PlaneCloud<float> target(target_cloud);
  const Isometry3d truth = frames.T_base_target();
  std::mt19937_64 rng(5);
  const Isometry3d initial = random_transform(rng, 2.0 * kDeg, 0.3) * truth;
  // One stage with a soft kernel is pulled by what only one sensor sees; coarse to fine is not.
  const auto r =
      ulc::register_point_to_plane(source, target, initial, ulc::coarse_to_fine_stages());
  INFO(ulc::to_string(r.status) << ", inliers " << r.inliers << " / " << r.source_points);
  REQUIRE(r.ok());
  const auto e = ulc::pose_error(truth, r.pose);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m");
  CHECK(e.rotation_deg < 0.05);
  CHECK(e.translation_m < 0.01);
}

TEST_CASE("a lone ground plane is degenerate and leaves the free directions alone",
          "[registration]") {
  std::mt19937_64 rng(3);
  std::vector<Vec3d> ground, ground2;
  sample_rectangle(ground, rng, Vec3d(-20, -20, 0), Vec3d::UnitX(), Vec3d::UnitY(), 40, 40, 4000,
                   0.005);
  sample_rectangle(ground2, rng, Vec3d(-20, -20, 0), Vec3d::UnitX(), Vec3d::UnitY(), 40, 40, 4000,
                   0.005);
  const ulc::PlaneCloud<double> target(to_cloud<double>(ground));
  // Lift the source 0.3 m and tilt it: z, roll and pitch are observable; x, y, yaw are not.
  Isometry3d lift = Isometry3d::Identity();
  lift.linear() = ulc::rotation_from_rpy(0.02, -0.01, 0.0);
  lift.translation() = Vec3d(0, 0, 0.3);
  const auto source = to_cloud<double>(transformed(ground2, lift));
  Isometry3d initial = Isometry3d::Identity();
  initial.translation() = Vec3d(0.7, -0.4, 0.0);  // a guess along the free directions
  const auto r = ulc::register_point_to_plane(source, target, initial);
  CHECK(r.status == RegistrationStatus::degenerate);
  CHECK(r.condition < 1e-4);
  // Observable part fixed: every source point lands on the plane z = 0.
  double worst = 0;
  for (const auto& p : source.points) worst = std::max(worst, std::abs((r.pose * p).z()));
  CHECK(worst < 0.03);
  // Free directions untouched: x, y at the guess, no yaw.
  CHECK(r.pose.translation().x() == Approx(0.7).margin(0.03));
  CHECK(r.pose.translation().y() == Approx(-0.4).margin(0.03));
  CHECK(std::abs(ulc::rpy_from_rotation(r.pose.linear())[2]) < 1e-3);
}

TEST_CASE("registration reports starved and invalid problems", "[registration]") {
  const auto scene = courtyard(1, 1000, 0.0);
  const ulc::PlaneCloud<double> target(to_cloud<double>(scene));
  ulc::RegistrationOptions o;

  SECTION("a source far from the target has no correspondences") {
    Isometry3d far = Isometry3d::Identity();
    far.translation() = Vec3d(500, 0, 0);
    const auto r = ulc::register_point_to_plane(to_cloud<double>(scene), target, far, o);
    CHECK(r.status == RegistrationStatus::too_few_correspondences);
    CHECK(r.correspondences == 0);
    CHECK(r.pose.isApprox(far));
  }
  SECTION("an empty source") {
    const auto r =
        ulc::register_point_to_plane(ulc::PointCloud<double>(), target, Isometry3d::Identity(), o);
    CHECK(r.status == RegistrationStatus::invalid_input);
  }
  SECTION("a non-finite initial pose") {
    Isometry3d bad = Isometry3d::Identity();
    bad.translation().x() = std::nan("");
    const auto r = ulc::register_point_to_plane(to_cloud<double>(scene), target, bad, o);
    CHECK(r.status == RegistrationStatus::invalid_input);
  }
  SECTION("bad options") {
    o.max_correspondence_distance = -1;
    const auto r =
        ulc::register_point_to_plane(to_cloud<double>(scene), target, Isometry3d::Identity(), o);
    CHECK(r.status == RegistrationStatus::invalid_input);
  }
  SECTION("one iteration is not enough from afar") {
    o.max_iterations = 1;
    std::mt19937_64 rng(2);
    const auto r = ulc::register_point_to_plane(to_cloud<double>(scene), target,
                                                random_transform(rng, 3 * kDeg, 0.5), o);
    CHECK(r.status == RegistrationStatus::not_converged);
    CHECK(r.iterations == 1);
  }
}

TEST_CASE("registration gives the same bits on 1 and 2 threads", "[registration][threads]") {
  const auto& frames = static_frames();
  const auto target_cloud = ulc::voxel_downsample(frames.frame(0, 0), 0.2).cloud;
  const auto source = ulc::voxel_downsample(frames.frame(1, 0), 0.3).cloud;
  const ulc::PlaneCloud<float> target(target_cloud);
  std::mt19937_64 rng(9);
  const Isometry3d initial = random_transform(rng, 2.0 * kDeg, 0.3) * frames.T_base_target();
  auto run = [&] { return ulc::register_point_to_plane(source, target, initial); };
  tbb::task_arena one(1), two(2);
  const auto r1 = one.execute(run);
  const auto r2 = two.execute(run);
  CHECK(r1.iterations == r2.iterations);
  CHECK(r1.correspondences == r2.correspondences);
  CHECK(same_bits(r1.pose, r2.pose));
  CHECK(same_bits(r1.cost, r2.cost));
  CHECK(same_bits(r1.hessian, r2.hessian));
}
