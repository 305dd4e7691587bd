// The ring gap (terra/ring_gap.hpp) read off a rendered frame of every spinning model: the
// median spacing of its laser table's elevations, which the ground vote fills.
#include <algorithm>
#include <catch2/catch.hpp>
#include <vector>

#include "terra/ring_gap.hpp"
#include "ulc/sim/simulate.hpp"

using namespace ulc::sim;

namespace {

double median_table_spacing(std::vector<double> elevations) {
  std::sort(elevations.begin(), elevations.end());
  std::vector<double> spacing;
  for (std::size_t k = 1; k < elevations.size(); ++k)
    if (elevations[k] - elevations[k - 1] > 1e-6)
      spacing.push_back(elevations[k] - elevations[k - 1]);
  std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
  return spacing[spacing.size() / 2];
}

}  // namespace

TEST_CASE("the ring gap of every spinning model's frame is its table's spacing",
          "[sim][ring_gap]") {
  for (const std::string& model : sensor_model_names()) {
    const SensorModel m = *sensor_model(model);
    if (!m.is_spinning()) continue;
    INFO(model);
    ScenarioSpec s;
    s.name = "single-" + model;
    s.lidars = {{"lidar", model, mount_pose(1.3, 0.0, 1.9, 0.0, 3.0, 0.0)}};
    SimulationOptions o;
    o.seconds = 0.3;
    o.seed = 9;
    Simulator sim;
    REQUIRE(sim.init(s, o).ok());
    ulc::PointCloud<float> frame;
    sim.render_frame(0, 1, frame);
    // Within two bins: rings closer than a bin or two merge (the HDL-64E's table is uneven).
    CHECK(
        terra::ring_gap_deg(frame) ==
        Approx(median_table_spacing(std::get<SpinningLidar>(m.pattern).elevation_deg)).margin(0.1));
  }
}
