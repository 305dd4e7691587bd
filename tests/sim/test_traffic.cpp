// Moving traffic: oncoming cars stay in the opposite lane, move against the ego vehicle, and
// the LiDARs see them at each ray's own instant.
#include <catch2/catch.hpp>
#include <cmath>

#include "ulc/sim/simulate.hpp"

using namespace ulc::sim;
using ulc::Isometry3d;
using ulc::Vec3d;

TEST_CASE("offset paths are exact parallels, also through turns", "[sim][traffic]") {
  Path2d p(Eigen::Vector2d(0, 0), 0.0);
  p.add_line(20);
  p.add_arc(7.0, -M_PI / 2);  // right turn
  p.add_line(15);
  p.add_arc(10.0, M_PI / 2);  // left turn
  p.add_line(30);
  const Path2d q = offset_path(p, 6.0);
  // Every point of q lies 6 m to the left of the point of p with the same heading.
  for (double s = 0; s < p.length(); s += 0.37) {
    const PathPoint a = p.at(s);
    const Eigen::Vector2d left(-std::sin(a.heading), std::cos(a.heading));
    double best = 1e9;
    for (double u = 0; u < q.length(); u += 0.01)
      best = std::min(best, (q.at(u).position - (a.position + 6.0 * left)).norm());
    REQUIRE(best < 0.01);
  }
}

TEST_CASE("oncoming cars keep to the opposite lane and drive against the ego vehicle",
          "[sim][traffic]") {
  const World world = build_world(SceneKind::town, 8, 600.0, 20.0);
  REQUIRE(world.traffic.cars().size() >= 10);
  int seen = 0;
  for (double t = 0.0; t < 60.0; t += 0.5) {
    std::vector<MovingBox> boxes;
    world.traffic.frame_boxes(t, t + 0.1, Vec3d(world.town.max_x() / 2, world.town.max_y() / 2, 0),
                              1e6, boxes);
    for (const MovingBox& b : boxes) {
      ++seen;
      const Vec3d c = b.box.center;
      // On the roadway, clear of the curb, and moving at a car's speed.
      REQUIRE(world.town.distance_to_street(c.x(), c.y()) <= world.town.road_half_width - 0.9);
      REQUIRE(b.velocity.norm() > 4.0);
      REQUIRE(b.velocity.norm() < 12.0);
      // The car's nose (its x axis) points along its velocity.
      CHECK(b.box.axes.col(0).dot(b.velocity.normalized()) > 0.95);
    }
  }
  CHECK(seen > 50);
}

TEST_CASE("LiDAR points land on passing cars at their own instants", "[sim][traffic]") {
  SimulationOptions o;
  o.seconds = 30.0;
  o.seed = 6;
  Simulator sim;
  ScenarioSpec spec = *scenario("64-32");
  spec.traffic_per_km = 40.0;
  REQUIRE(sim.init(spec, o).ok());
  // The first frame of the HDL-64E with a car within 20 m.
  std::vector<MovingBox> near;
  std::size_t k = 0;
  for (; k < sim.frame_count(0); ++k) {
    const double t0 = sim.frame_start(0, k);
    sim.world().traffic.frame_boxes(t0, t0 + 0.1, sim.trajectory().pose(t0).translation(), 20.0,
                                    near);
    if (!near.empty()) break;
  }
  REQUIRE(k < sim.frame_count(0));
  ulc::PointCloud<float> frame;
  sim.render_frame(0, k, frame);
  const double t0 = sim.frame_start(0, k);
  std::size_t on_cars = 0, on_cars_frozen = 0;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    const Vec3d p = sim.T_world_lidar(0, t0 + frame.times[i]) * frame.points[i].cast<double>();
    for (const MovingBox& m : near) {
      auto inside = [&](double dt) {
        const Vec3d local = m.box.axes.transpose() * (p - (m.box.center + m.velocity * dt));
        return (local.cwiseAbs() - m.box.half).maxCoeff() < 0.1;
      };
      on_cars += inside(frame.times[i]) ? 1 : 0;
      on_cars_frozen += inside(0.0) ? 1 : 0;
    }
  }
  INFO("points on cars " << on_cars << ", against cars frozen at the frame start "
                         << on_cars_frozen);
  CHECK(on_cars > 20);
  CHECK(on_cars > on_cars_frozen);  // the cars were seen moving, not as at the frame start
}
