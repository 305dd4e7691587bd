// Deskewing under constant velocity: a sensor moving with a known twist measures a static scene;
// deskewing with the true sweep motion gives back the scene as seen from the sweep's start.
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "registration_test_util.hpp"
#include "ulc/core/deskew.hpp"

using namespace reg_test;

namespace {

struct Sweep {
  ulc::PointCloud<double> cloud;  ///< measured: each point in the sensor frame of its instant
  std::vector<Vec3d> truth;       ///< the same points in the sensor frame at the sweep start
  std::vector<double> fractions;
};

/// A sensor at T0 moving with body twist xi (per second) measures `world` over `duration`.
Sweep measure(const std::vector<Vec3d>& world, const Isometry3d& T0, const Vec6d& xi,
              double duration, double first_fraction, double last_fraction) {
  Sweep s;
  const std::size_t n = world.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double f = first_fraction + (last_fraction - first_fraction) * i / (n - 1.0);
    const Isometry3d T = T0 * ulc::se3_exp(Vec6d(f * duration * xi));
    s.cloud.points.push_back(T.inverse() * world[i]);
    s.cloud.times.push_back(f * duration);
    s.truth.push_back(T0.inverse() * world[i]);
    s.fractions.push_back(f);
  }
  return s;
}

}  // namespace

TEST_CASE("deskewing with the true motion restores the scene at the sweep start",
          "[registration][deskew]") {
  const auto world = courtyard(1, 2000, 0.0);
  std::mt19937_64 rng(2);
  const Isometry3d T0 = random_transform(rng, 0.7, 30.0);
  // 15 m/s forward, 30 deg/s yaw, some pitch and roll rate: a fast, turning car.
  Vec6d xi;
  xi << 15.0, 0.3, -0.2, 0.05, -0.1, 30.0 * kDeg;
  const double duration = 0.1;
  const Isometry3d sweep = ulc::sweep_motion_from_twist(xi, duration);

  SECTION("points inside the sweep, through the tabulated motion") {
    Sweep s = measure(world, T0, xi, duration, 0.0, 1.0);
    double before = 0, after = 0;
    for (std::size_t i = 0; i < s.truth.size(); ++i)
      before = std::max(before, (s.cloud.points[i] - s.truth[i]).norm());
    auto points = s.cloud.points;
    ulc::deskew_points(points, s.fractions, sweep);
    for (std::size_t i = 0; i < s.truth.size(); ++i)
      after = std::max(after, (points[i] - s.truth[i]).norm());
    CHECK(before > 1.0);  // the distortion is real
    CHECK(after < 1e-5);  // and gone
    const auto cloud = ulc::deskew(s.cloud, sweep, duration);
    REQUIRE(cloud.size() == s.truth.size());
    CHECK_FALSE(cloud.has_times());
    for (std::size_t i = 0; i < s.truth.size(); ++i)
      CHECK((cloud.points[i] - points[i]).norm() < 1e-9);
  }
  SECTION("fractions outside the sweep extrapolate exactly") {
    Sweep s = measure(world, T0, xi, duration, -0.2, 1.3);
    auto points = s.cloud.points;
    ulc::deskew_points(points, s.fractions, sweep);
    double after = 0;
    for (std::size_t i = 0; i < s.truth.size(); ++i)
      after = std::max(after, (points[i] - s.truth[i]).norm());
    CHECK(after < 1e-5);
  }
  SECTION("no times or no motion: the points are copied") {
    ulc::PointCloud<float> untimed;
    for (const Vec3d& p : world) untimed.points.push_back(p.cast<float>());
    const auto a = ulc::deskew(untimed, sweep, duration);
    Sweep s = measure(world, T0, xi, duration, 0.0, 1.0);
    const auto b = ulc::deskew(s.cloud, Isometry3d::Identity(), duration);
    for (std::size_t i = 0; i < world.size(); ++i) {
      CHECK(a.points[i] == untimed.points[i]);
      CHECK(b.points[i] == s.cloud.points[i]);
    }
  }
}
