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

namespace {

/// A line, a 90 deg left arc of radius 12 m, and a line: one line-arc junction at s = 60 m.
Path2d corner_route() {
  Path2d path(Eigen::Vector2d(0.0, 0.0), 0.0);
  path.add_line(60.0);
  path.add_arc(12.0, M_PI / 2);
  path.add_line(300.0);
  return path;
}

}  // namespace

TEST_CASE("path position integral matches numerical integration", "[sim][trajectory]") {
  const Path2d path = corner_route();
  for (double s : {-3.0, 0.0, 10.0, 59.0, 65.0, 78.0, 300.0, path.length() + 20.0}) {
    // Midpoint rule from -5 m to s (the path extended straight back before 0), with the
    // integral's own value at -5 m as the start.
    const int n = 200000;
    const double a = -5.0, h = (s - a) / n;
    Eigen::Vector2d sum = path.position_integral(a);
    for (int i = 0; i < n; ++i) sum += h * path.extended_at(a + (i + 0.5) * h).position;
    INFO("s = " << s);
    CHECK((path.position_integral(s) - sum).norm() < 1e-4);
  }
}

TEST_CASE("averaged path: unchanged on lines, inside arcs, curvature ramps over the window",
          "[sim][trajectory]") {
  const Path2d path = corner_route();
  const double L = 6.0, R = 12.0;
  // Far from the junctions it is the path itself on a line ...
  const PathPoint on_line = path.averaged(30.0, L);
  CHECK((on_line.position - path.at(30.0).position).norm() < 1e-9);
  CHECK(on_line.heading == Approx(0.0).margin(1e-12));
  CHECK(on_line.curvature == Approx(0.0).margin(1e-12));
  // ... and L^2 / (24 R) inside it in the middle of the arc, with the arc's heading and curvature.
  const double mid = 60.0 + R * M_PI / 4;
  const PathPoint on_arc = path.averaged(mid, L), exact = path.at(mid);
  const Eigen::Vector2d centre(60.0, R);
  const double inside = R - (on_arc.position - centre).norm();
  CHECK(inside == Approx(L * L / (24 * R)).epsilon(0.01));
  CHECK(on_arc.heading == Approx(exact.heading).margin(1e-9));
  CHECK(on_arc.curvature == Approx(1.0 / R).epsilon(1e-9));
  // Across the junction the curvature ramps from 0 to 1/R over [60 - L/2, 60 + L/2]: no step,
  // and it is the heading's rate (central differences).
  double max_step = 0.0;
  for (double s = 50.0; s < 70.0; s += 0.01) {
    const double k0 = path.averaged(s, L).curvature, k1 = path.averaged(s + 0.01, L).curvature;
    max_step = std::max(max_step, std::abs(k1 - k0));
    const double rate =
        (path.averaged(s + 1e-4, L).heading - path.averaged(s - 1e-4, L).heading) / 2e-4;
    INFO("s = " << s);
    CHECK(rate == Approx(k0).margin(1e-5));
  }
  CHECK(max_step < 1.5 * 0.01 / (L * R));  // a ramp of slope 1 / (L R)
  CHECK(path.averaged(60.0 - L / 2 - 0.01, L).curvature == Approx(0.0).margin(1e-9));
  CHECK(path.averaged(60.0 + L / 2 + 0.01, L).curvature == Approx(1.0 / R).epsilon(1e-6));
  // Without a window the curvature steps at the junction.
  CHECK(path.averaged(60.0 + 1e-6, 0.0).curvature - path.averaged(60.0 - 1e-6, 0.0).curvature ==
        Approx(1.0 / R));
}

TEST_CASE("steering ramp: yaw rate and body roll ramp in instead of stepping into a turn",
          "[sim][trajectory]") {
  MotionSpec motion;
  motion.bumps = false;
  auto largest_change_per_ms = [&](double ramp) {
    motion.steering_ramp_m = ramp;
    const VehicleTrajectory traj(corner_route(), GroundRelief(), motion, 7, 40.0);
    double roll_step = 0.0, yaw_rate_step = 0.0, prev_rate = 0.0;
    ulc::Vec3d prev = ulc::rpy_from_rotation(traj.pose(0.0).linear());
    for (double t = 1e-3; t < 40.0; t += 1e-3) {
      const ulc::Vec3d rpy = ulc::rpy_from_rotation(traj.pose(t).linear());
      const double rate = std::remainder(rpy.z() - prev.z(), 2 * M_PI) / 1e-3;
      roll_step = std::max(roll_step, std::abs(rpy.x() - prev.x()));
      if (t > 2e-3) yaw_rate_step = std::max(yaw_rate_step, std::abs(rate - prev_rate));
      prev = rpy;
      prev_rate = rate;
    }
    return std::make_pair(roll_step, yaw_rate_step);
  };
  const auto [roll_step, yaw_rate_step] = largest_change_per_ms(0.0);
  const auto [ramped_roll_step, ramped_yaw_rate_step] = largest_change_per_ms(6.0);
  // Turn speed sqrt(2 / (1/12)) ~ 4.9 m/s: a 0.016 rad roll and a 0.4 rad/s yaw-rate step.
  CHECK(roll_step > 0.01);
  CHECK(yaw_rate_step > 0.3);
  CHECK(ramped_roll_step < 1e-4);
  CHECK(ramped_yaw_rate_step < 1e-2);
}
