// The motion frame (pipeline/motion_frame.hpp) on views written by the test: two LiDARs of one
// vehicle, the target turned by a known rotation, each seeing the road and a wall along it.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "pipeline/motion_frame.hpp"
#include "terra/random_rotation.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"

namespace {

constexpr double kMotionDeg = 3.14159265358979323846 / 180.0;

terra::PlaneFit plane(const ulc::Vec3d& normal, double offset, std::size_t inliers) {
  terra::PlaneFit p;
  p.ok = true;
  p.normal = normal.normalized();
  p.offset = offset;
  p.inliers = inliers;
  p.used = 20000;  // the map's usable points (largest_planes: the first plane's `used`)
  return p;
}

/// The base's view: 12 m of travel along x, the road 1.8 m below, a wall 4 m to the left.
ulc::MotionView base_view() {
  ulc::MotionView v;
  v.travel = ulc::Vec3d(12.0, 0.3, 0.05);
  v.planes = {plane(ulc::Vec3d::UnitZ(), 1.8, 9000), plane(-ulc::Vec3d::UnitY(), 4.0, 3000)};
  return v;
}

/// The same surfaces and travel seen by a target turned by R = R_base_target, 0.5 m higher and
/// 0.3 m to the right; `wall_first` lists the wall as its largest plane.
ulc::MotionView target_view(const ulc::Mat3d& R, bool wall_first) {
  const ulc::MotionView a = base_view();
  ulc::MotionView v;
  v.travel = R.transpose() * a.travel;
  const terra::PlaneFit road = plane(R.transpose() * a.planes[0].normal, 2.3, 5000);
  const terra::PlaneFit wall = plane(R.transpose() * a.planes[1].normal, 4.3, 6000);
  v.planes = wall_first ? std::vector<terra::PlaneFit>{wall, road}
                        : std::vector<terra::PlaneFit>{road, wall};
  return v;
}

}  // namespace

TEST_CASE("the motion frame recovers any rotation from the ground and the travel",
          "[calibrate][motion_frame]") {
  terra::SplitMix64 rng(5);
  const ulc::MotionFrameOptions o;
  for (int k = 0; k < 20; ++k) {
    const ulc::Mat3d R = terra::random_rotation(rng);
    const ulc::MotionReport m = ulc::motion_rotation(base_view(), target_view(R, k % 2 == 1), o);
    REQUIRE(m.ok);
    // Exact views: the triad is exact (the travel's small climb is projected out on both sides).
    CHECK(ulc::rotation_error_rad(R, m.rotation) / kMotionDeg < 1e-6);
    CHECK(m.planes_matched == 2);
  }
}

TEST_CASE("a wall along the street is not taken for the ground", "[calibrate][motion_frame]") {
  // The target's largest plane is the wall; it holds the travel as the road does. Taken for the
  // ground it turns the road onto the wall's direction at another distance: one surface
  // matches instead of two.
  const ulc::Mat3d R = ulc::rotation_from_rpy(0.4, -1.1, 2.5);
  const ulc::MotionReport m = ulc::motion_rotation(base_view(), target_view(R, true), {});
  REQUIRE(m.ok);
  CHECK(ulc::rotation_error_rad(R, m.rotation) / kMotionDeg < 1e-6);
}

TEST_CASE("an overhang above both sensors is not taken for the road", "[calibrate][motion_frame]") {
  // Two horizontal surfaces above the sensors, facing down (a canopy, a bridge deck): taken for
  // the ground they would turn the rig upside down, and the road would match the overhangs.
  terra::SplitMix64 rng(9);
  for (int k = 0; k < 10; ++k) {
    const ulc::Mat3d R = terra::random_rotation(rng);
    ulc::MotionView a = base_view(), b = target_view(R, false);
    a.planes.push_back(plane(-ulc::Vec3d::UnitZ(), 0.7, 800));
    a.planes.push_back(plane(-ulc::Vec3d::UnitZ(), 2.0, 700));
    b.planes.push_back(plane(R.transpose() * -ulc::Vec3d::UnitZ(), 1.9, 700));
    b.planes.push_back(plane(R.transpose() * ulc::Vec3d::UnitZ(), 2.0, 650));  // a curb
    const ulc::MotionReport m = ulc::motion_rotation(a, b, {});
    REQUIRE(m.ok);
    CHECK(ulc::rotation_error_rad(R, m.rotation) / kMotionDeg < 1e-6);
  }
}

TEST_CASE("the motion frame refuses a parked rig, slipping odometry and no shared ground",
          "[calibrate][motion_frame]") {
  const ulc::Mat3d R = ulc::rotation_from_rpy(0.1, 0.2, 0.3);
  const ulc::MotionFrameOptions o;
  SECTION("parked") {
    ulc::MotionView a = base_view(), b = target_view(R, false);
    a.travel *= 0.1;
    b.travel *= 0.1;
    const auto m = ulc::motion_rotation(a, b, o);
    CHECK_FALSE(m.ok);
    CHECK(m.reason.find("travelled 1.20 m") != std::string::npos);
  }
  SECTION("the target's odometry travelled 20 % less") {
    ulc::MotionView b = target_view(R, false);
    b.travel *= 0.8;
    const auto m = ulc::motion_rotation(base_view(), b, o);
    CHECK_FALSE(m.ok);
    CHECK(m.reason.find("disagree on the distance") != std::string::npos);
  }
  SECTION("the target sees no plane that holds the travel") {
    ulc::MotionView b = target_view(R, false);
    b.planes = {plane(R.transpose() * ulc::Vec3d::UnitX(), 6.0, 4000)};  // a wall ahead
    const auto m = ulc::motion_rotation(base_view(), b, o);
    CHECK_FALSE(m.ok);
    CHECK(m.reason.find("no ground both maps share") != std::string::npos);
  }
  SECTION("the heights differ by more than the mounts can: no surface in common") {
    ulc::MotionView b = target_view(R, false);
    for (auto& p : b.planes) p.offset += 5.0;
    CHECK_FALSE(ulc::motion_rotation(base_view(), b, o).ok);
  }
}

TEST_CASE("largest_planes finds the road, then the walls, largest first",
          "[calibrate][motion_frame]") {
  // A street written by the test: 40 x 16 m of road 1.8 m below the sensor, a 40 x 6 m wall
  // 5 m to the left, a 40 x 3 m wall 7 m to the right, every 0.2 m.
  std::vector<ulc::Vec3d> cloud;
  for (double x = -20.0; x <= 20.0; x += 0.2) {
    for (double y = -7.0; y <= 5.0; y += 0.2) cloud.emplace_back(x, y, -1.8);
    for (double z = -1.8; z <= 4.2; z += 0.2) cloud.emplace_back(x, 5.0, z);
    for (double z = -1.8; z <= 1.2; z += 0.2) cloud.emplace_back(x, -7.0, z);
  }
  const auto planes = terra::largest_planes(cloud, 4, 100);
  REQUIRE(planes.size() == 3);
  CHECK(planes[0].normal.dot(ulc::Vec3d::UnitZ()) > std::cos(0.5 * kMotionDeg));
  CHECK(planes[0].offset == Approx(1.8).margin(0.02));
  CHECK(planes[1].normal.dot(-ulc::Vec3d::UnitY()) > std::cos(0.5 * kMotionDeg));
  CHECK(planes[1].offset == Approx(5.0).margin(0.02));
  CHECK(planes[2].normal.dot(ulc::Vec3d::UnitY()) > std::cos(0.5 * kMotionDeg));
  CHECK(planes[2].offset == Approx(7.0).margin(0.02));
  CHECK(planes[0].inliers > planes[1].inliers);
  CHECK(planes[1].inliers > planes[2].inliers);
}
