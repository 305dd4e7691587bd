// Rendered frames of every sensor model: inside the model's FoV and range, times nondecreasing
// in firing order and spanning one sweep, intensities in range, nothing seen through the
// vehicle's own body.
#include <catch2/catch.hpp>
#include <cmath>

#include "ulc/sim/simulate.hpp"

using namespace ulc::sim;
using ulc::Vec3d;

namespace {

ScenarioSpec single(const std::string& model, const ulc::Isometry3d& mount) {
  ScenarioSpec s;
  s.name = "single-" + model;
  s.lidars = {{"lidar", model, mount}};
  return s;
}

}  // namespace

TEST_CASE("every model's rendered points stay inside its FoV and range, in firing order",
          "[sim][frames]") {
  for (const std::string& model : sensor_model_names()) {
    for (double rate : {10.0, 20.0}) {
      INFO(model << " at " << rate << " Hz");
      const SensorModel m = *sensor_model(model);
      // Roof mount, pitched a little down so forward-looking units see the street.
      SimulationOptions o;
      o.seconds = 2.0 / rate;
      o.seed = 9;
      o.rate_hz = rate;
      o.decimation = m.is_spinning() ? 4 : 2;
      o.static_at_s = 7.0;
      Simulator sim;
      REQUIRE(sim.init(single(model, mount_pose(1.3, 0.0, 1.9, 0.0, 3.0, 0.0)), o).ok());
      const FieldOfView fov = m.fov();
      const double beam_origin =
          m.is_spinning() ? std::get<SpinningLidar>(m.pattern).beam_origin_radius : 0.0;
      const double margin = beam_origin > 0.0 ? 0.02 : 1e-5;  // rad
      const double slack = 6.0 * m.range.range_sigma + m.range.range_resolution + beam_origin;
      for (std::size_t k = 0; k < 2; ++k) {
        ulc::PointCloud<float> cloud;
        sim.render_frame(0, k, cloud);
        REQUIRE(cloud.size() > 200);
        REQUIRE(cloud.has_times());
        REQUIRE(cloud.has_intensities());
        bool in_fov = true, in_range = true, ordered = true, bright = true;
        for (std::size_t i = 0; i < cloud.size(); ++i) {
          const Vec3d p = cloud.points[i].cast<double>();
          const double r = p.norm();
          in_range = in_range && r >= m.range.min_range - slack && r <= m.range.max_range + slack;
          if (r > 2.0) in_fov = in_fov && fov.contains(p / r, margin);
          if (i > 0) ordered = ordered && cloud.times[i] >= cloud.times[i - 1];
          bright = bright && cloud.intensities[i] >= 0.0f && cloud.intensities[i] <= 255.0f;
        }
        CHECK(in_fov);
        CHECK(in_range);
        CHECK(ordered);
        CHECK(bright);
        CHECK(cloud.times.front() >= 0.0);
        CHECK(cloud.times.back() < 1.0 / rate);
        CHECK(cloud.times.back() - cloud.times.front() > 0.8 / rate);  // one sweep
      }
    }
  }
}

TEST_CASE("the vehicle's body blocks its sensors: nothing seen under or through the car",
          "[sim][frames]") {
  SimulationOptions o;
  o.seconds = 0.1;
  o.static_at_s = 3.0;
  for (const char* name : {"64-32", "ring-5x16", "side-bpearl"}) {
    INFO(name);
    Simulator sim;
    REQUIRE(sim.init(*scenario(name), o).ok());
    std::size_t total = 0;
    for (std::size_t l = 0; l < sim.lidar_count(); ++l) {
      ulc::PointCloud<float> cloud;
      sim.render_frame(l, 0, cloud);
      total += cloud.size();
      const ulc::Isometry3d T = sim.spec().lidars[l].T_vehicle_lidar;
      std::size_t inside = 0;
      for (const auto& p : cloud.points) {
        const Vec3d v = T * p.cast<double>();
        inside += (v.x() > -0.9 && v.x() < 3.7 && std::abs(v.y()) < 0.9 && v.z() < 1.5) ? 1 : 0;
      }
      CHECK(inside == 0);
    }
    CHECK(total > 10000);
  }
}
