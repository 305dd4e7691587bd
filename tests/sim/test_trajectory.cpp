// Vehicle motion: stays on the town's streets (no driving through anything) for well over
// 120 s, realistic speeds and attitudes, continuous in time; degenerate scenes drive straight.
#include <catch2/catch.hpp>
#include <cmath>

#include "ulc/core/lie.hpp"
#include "ulc/sim/scenario.hpp"
#include "ulc/sim/trajectory.hpp"
#include "ulc/sim/world.hpp"

using namespace ulc::sim;
using ulc::Isometry3d;
using ulc::Vec3d;

namespace {

double heading_of(const Isometry3d& T) {
  return std::atan2(T.linear()(1, 0), T.linear()(0, 0));
}

/// Does any scene object (not the ground) occupy the vehicle's body at pose T? Probes with
/// horizontal rays from the body centre at two heights towards the body's sides and ends.
bool body_is_clear(const Scene& scene, const Isometry3d& T) {
  for (double z : {0.6, 1.3}) {
    const Vec3d centre = T * Vec3d(1.4, 0.0, z);
    for (int k = 0; k < 16; ++k) {
      const double a = 2 * M_PI * k / 16;
      const Vec3d local(std::cos(a), std::sin(a), 0.0);
      // Distance from the centre to the body's boundary (4.7 x 1.9 m box) in that direction.
      const double reach =
          std::min(std::abs(2.35 / (local.x() + 1e-12)), std::abs(0.95 / (local.y() + 1e-12)));
      Ray ray;
      ray.origin = centre;
      ray.dir = T.linear() * local;
      ray.t_max = reach;
      SurfaceHit hit;
      if (scene.intersect(ray, hit)) return false;
    }
  }
  return true;
}

}  // namespace

TEST_CASE("town drive: on the streets, clear of every object, for 130 s", "[sim][trajectory]") {
  const double duration = 130.0;
  const MotionSpec motion;
  const World world = build_world(SceneKind::town, 21, motion.max_speed * (duration + 2) + 50);
  const VehicleTrajectory traj(world.route, world.ground, motion, 5, duration);
  double min_speed = 1e9, max_speed = 0, max_tilt = 0, max_roll = 0, turned = 0;
  double prev_heading = heading_of(traj.pose(0.0));
  for (double t = 0.0; t <= duration; t += 0.05) {
    const Isometry3d T = traj.pose(t);
    INFO("t = " << t);
    const Vec3d p = T.translation();
    // Lane centre within the roadway with room for the car's half width.
    REQUIRE(world.town.distance_to_street(p.x(), p.y()) <= world.town.road_half_width - 1.0);
    REQUIRE(p.z() == Approx(world.ground.height(p.x(), p.y())).margin(0.1));  // on the road
    REQUIRE(body_is_clear(world.scene, T));
    const double v = traj.speed(t);
    min_speed = std::min(min_speed, v);
    max_speed = std::max(max_speed, v);
    const ulc::Vec3d rpy = ulc::rpy_from_rotation(T.linear());
    max_tilt = std::max(max_tilt, std::max(std::abs(rpy.x()), std::abs(rpy.y())));
    max_roll = std::max(max_roll, std::abs(rpy.x()));
    const double h = heading_of(T);
    turned += std::abs(std::remainder(h - prev_heading, 2 * M_PI));
    prev_heading = h;
  }
  CHECK(min_speed >= motion.min_speed - 1e-9);
  CHECK(max_speed <= motion.max_speed + 1e-9);
  CHECK(max_speed - min_speed > 5.0);  // real speed changes
  CHECK(max_tilt < 5.0 * M_PI / 180);  // small pitch and roll ...
  CHECK(max_roll > 0.3 * M_PI / 180);  // ... but not none
  CHECK(turned > M_PI);                // it turns at intersections
  CHECK(traj.distance(duration) > 500.0);
  // The probe does see obstacles: shifted 25 m sideways into the blocks, the car collides.
  int blocked = 0;
  for (double t = 0.0; t < duration; t += 5.0) {
    Isometry3d T = traj.pose(t);
    T.translation() += T.linear() * Vec3d(0.0, -25.0, 0.0);
    blocked += body_is_clear(world.scene, T) ? 0 : 1;
  }
  CHECK(blocked > 10);
}

TEST_CASE("pose is continuous and its velocity matches the speed profile", "[sim][trajectory]") {
  const World world = build_world(SceneKind::town, 2, 400);
  const VehicleTrajectory traj(world.route, world.ground, MotionSpec{}, 3, 30.0);
  for (double t = 0.3; t < 29.0; t += 0.731) {
    const double h = 1e-4;
    const Vec3d v = (traj.pose(t + h).translation() - traj.pose(t - h).translation()) / (2 * h);
    INFO("t = " << t);
    CHECK(v.head<2>().norm() == Approx(traj.speed(t)).epsilon(0.01));
    CHECK(traj.distance(t + h) - traj.distance(t - h) ==
          Approx(2 * h * traj.speed(t)).epsilon(1e-3));
    // No jumps: poses 1 ms apart are close in translation and rotation.
    const Isometry3d d = traj.pose(t).inverse() * traj.pose(t + 1e-3);
    CHECK(d.translation().norm() < 0.02);
    CHECK(Eigen::AngleAxisd(d.linear()).angle() < 2e-3);
  }
}

TEST_CASE("pose table interpolates the exact pose to sub-millimetre", "[sim][trajectory]") {
  const World world = build_world(SceneKind::town, 2, 400);
  const VehicleTrajectory traj(world.route, world.ground, MotionSpec{}, 3, 20.0);
  const PoseTable table(traj, 0.0, 20.0);
  for (double t = 0.0005; t < 19.9; t += 0.1234567) {
    ulc::Mat3d R;
    Vec3d p;
    table.at(t, R, p);
    const Isometry3d T = traj.pose(t);
    CHECK((p - T.translation()).norm() < 1e-5);
    CHECK((R - T.linear()).norm() < 1e-6);
  }
}

TEST_CASE("frozen trajectory stays put; lift motion moves vertically", "[sim][trajectory]") {
  const World world = build_world(SceneKind::town, 2, 400);
  VehicleTrajectory parked(world.route, world.ground, MotionSpec{}, 3, 20.0);
  parked.freeze_at(4.0);
  CHECK(parked.pose(0.0).isApprox(parked.pose(15.0), 1e-15));
  CHECK(parked.speed(3.0) == 0.0);
  MotionSpec lift;
  lift.lift_amplitude = 4.0;
  lift.lift_period = 20.0;
  lift.bumps = false;
  const VehicleTrajectory lifted(world.route, world.ground, lift, 3, 20.0);
  double dz_max = 0;
  for (double t = 0; t <= 20.0; t += 0.5) {
    const Vec3d p = lifted.pose(t).translation();
    dz_max = std::max(dz_max, p.z() - world.ground.height(p.x(), p.y()));
  }
  CHECK(dz_max == Approx(4.0).margin(0.05));
}

TEST_CASE("tunnel: straight through along +x; highway: straight-ish", "[sim][trajectory]") {
  const ScenarioSpec tunnel_spec = *scenario("tunnel");
  const double duration = 40.0;
  const World tunnel =
      build_world(SceneKind::tunnel, 1, tunnel_spec.motion.max_speed * duration + 50);
  const VehicleTrajectory t1(tunnel.route, tunnel.ground, tunnel_spec.motion, 1, duration);
  CHECK(t1.pose(0.0).translation().x() < tunnel.tunnel.start_x);
  CHECK(t1.pose(duration).translation().x() > tunnel.tunnel.start_x + 300.0);
  for (double t = 0; t <= duration; t += 1.0) {
    const Isometry3d T = t1.pose(t);
    CHECK(std::abs(heading_of(T)) < 1e-9);
    CHECK(T.translation().y() == Approx(tunnel.tunnel.lane_offset));
    CHECK(body_is_clear(tunnel.scene, T));
  }
  const World highway = build_world(SceneKind::highway, 1, 12.0 * duration + 50);
  const VehicleTrajectory t2(highway.route, highway.ground, tunnel_spec.motion, 1, duration);
  double max_heading = 0;
  for (double t = 0; t <= duration; t += 0.5) {
    const Isometry3d T = t2.pose(t);
    max_heading = std::max(max_heading, std::abs(heading_of(T)));
    REQUIRE(body_is_clear(highway.scene, T));
  }
  CHECK(max_heading < 15.0 * M_PI / 180);
  CHECK(max_heading > 0.5 * M_PI / 180);  // it does bend a little
}
