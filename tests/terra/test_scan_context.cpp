#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "terra/plane_fit.hpp"
#include "terra/scan_context.hpp"
#include "terra_test_util.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"

using terra_test::kDeg;

TEST_CASE("largest plane of a street scan is the ground, normal up", "[scancontext]") {
  const ulc::Mat3d tilt = ulc::rotation_from_rpy(0.2, -0.1, 0.7);
  const auto cloud = terra_test::scan(tilt);  // the LiDAR turned: its ground normal is tilt^T z
  const auto fit = terra::largest_plane(cloud);
  REQUIRE(fit.ok);
  const ulc::Vec3d up_in_lidar = tilt.transpose() * ulc::Vec3d::UnitZ();
  CHECK(fit.normal.dot(up_in_lidar) > std::cos(0.5 * kDeg));
  CHECK(fit.offset == Approx(2.0).margin(0.05));  // the sensor is 2 m above the ground
  // Same seed, same plane.
  const auto again = terra::largest_plane(cloud);
  CHECK(again.normal == fit.normal);
}

TEST_CASE("scancontext* recovers roll, pitch and yaw when the ground is visible", "[scancontext]") {
  const auto base = terra_test::scan(ulc::Mat3d::Identity(), ulc::Vec3d::Zero(), 64, 1024);
  const std::vector<ulc::Mat3d> truths = {
      ulc::rotation_from_rpy(0.05, -0.08, 1.3),
      ulc::rotation_from_rpy(-0.1, 0.15, -2.6),
      ulc::rotation_from_rpy(0.0, 0.0, 0.02),
  };
  for (const auto& R_gt : truths) {
    const auto target = terra_test::scan(R_gt, ulc::Vec3d(0.3, -0.2, 0.1), 64, 1024);
    const auto result = terra::scan_context_rotation(base, target);
    REQUIRE(result.ok);
    const double error_deg = ulc::rotation_error_rad(R_gt, result.rotation) / kDeg;
    INFO("error " << error_deg << " deg");
    CHECK(error_deg < 3.0);
  }
}

TEST_CASE("scancontext* fails cleanly without a plane", "[scancontext]") {
  const std::vector<ulc::Vec3d> too_few = {{1, 0, 0}, {0, 1, 0}};
  const auto result = terra::scan_context_rotation(too_few, too_few);
  CHECK(!result.ok);
  CHECK(result.reason.find("no plane") != std::string::npos);
}
