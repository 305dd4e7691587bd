// Named scenarios and rigs: every required name exists and is valid, mounts are realistic
// (0.5..3 m apart, non-trivial rotations, outside the body), pair truths follow from the mounts,
// and clock offsets follow the docs/design.md convention.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "ulc/sim/simulate.hpp"

using namespace ulc::sim;
using ulc::Isometry3d;
using ulc::Vec3d;

namespace {

double angle_deg(const ulc::Mat3d& R) {
  return Eigen::AngleAxisd(R).angle() * 180.0 / M_PI;
}

}  // namespace

TEST_CASE("the paper's scenarios and the special rigs all exist and are valid", "[sim][scenario]") {
  const std::vector<std::string> required = {
      "64-32",       "32-16",       "horizon-tele", "64-horizon", "32-avia",    "64-tele",
      "16-tele",     "32-mid40",    "colorful",     "ring-5x16",  "pitched-90", "side-bpearl",
      "upside-down", "offset-50ms", "highway",      "tunnel"};
  const auto names = scenario_names();
  for (const auto& name : required) {
    INFO(name);
    CHECK(std::find(names.begin(), names.end(), name) != names.end());
  }
  for (const auto& name : names) {
    INFO(name);
    const auto spec = scenario(name);
    REQUIRE(spec);
    CHECK(spec->name == name);
    const ScenarioCheck check = check_scenario(*spec);
    CHECK(check.ok);
    CHECK(check.reason.empty());
    CHECK_FALSE(spec->pairs.empty());
    CHECK_FALSE(spec->description.empty());
  }
  CHECK_FALSE(scenario("64-33").has_value());
}

TEST_CASE("pair scenarios: the first named LiDAR is the base, models as in the paper",
          "[sim][scenario]") {
  const std::vector<std::tuple<std::string, std::string, std::string>> pairs = {
      {"64-32", "HDL-64E", "VLP-32C"},        {"32-16", "VLP-32C", "VLP-16"},
      {"horizon-tele", "Horizon", "Tele-15"}, {"64-horizon", "HDL-64E", "Horizon"},
      {"32-avia", "VLP-32C", "Avia"},         {"64-tele", "HDL-64E", "Tele-15"},
      {"16-tele", "VLP-16", "Tele-15"},       {"32-mid40", "VLP-32C", "Mid-40"}};
  const ScenarioSpec colorful = *scenario("colorful");
  for (const auto& [name, base, target] : pairs) {
    INFO(name);
    const ScenarioSpec s = *scenario(name);
    REQUIRE(s.lidars.size() == 2);
    CHECK(s.lidars[0].model == base);
    CHECK(s.lidars[1].model == target);
    REQUIRE(s.pairs.size() == 1);
    CHECK(s.pairs[0].base == s.lidars[0].name);
    CHECK(s.pairs[0].target == s.lidars[1].name);
    CHECK(s.lidars[0].rate_hz == 10.0);
    // Same mounts as on the COLORFUL rig, so the ground truths agree.
    const LidarMount* m = colorful.find(s.lidars[1].name);
    REQUIRE(m);
    CHECK(m->T_vehicle_lidar.isApprox(s.lidars[1].T_vehicle_lidar));
  }
  CHECK(colorful.lidars.size() == 7);
  CHECK(colorful.pairs.size() == 8);
  for (const auto& m : colorful.lidars) CHECK(m.rate_hz == 20.0);
}

TEST_CASE("mounts: 0.5..3 m apart, non-trivial rotations, outside the body, housings apart",
          "[sim][scenario]") {
  const VehicleBody body = VehicleBody::car();
  for (const auto& name : scenario_names()) {
    INFO(name);
    const ScenarioSpec s = *scenario(name);
    for (const PairTruth& p : pair_truths(s)) {
      INFO(p.base << " -> " << p.target);
      const double d = p.T_base_target.translation().norm();
      CHECK(d >= 0.5);
      CHECK(d <= 3.0);
      CHECK(angle_deg(p.T_base_target.linear()) > 1.0);
    }
    for (std::size_t i = 0; i < s.lidars.size(); ++i) {
      const Vec3d pi = s.lidars[i].T_vehicle_lidar.translation();
      const Vec3d hi = sensor_model(s.lidars[i].model)->housing_half;
      CHECK_FALSE(body.contains(pi));
      // Housing corners outside the body too.
      for (int c = 0; c < 8; ++c) {
        const Vec3d corner(c & 1 ? hi.x() : -hi.x(), c & 2 ? hi.y() : -hi.y(),
                           c & 4 ? hi.z() : -hi.z());
        CHECK_FALSE(body.contains(s.lidars[i].T_vehicle_lidar * corner));
      }
      for (std::size_t j = 0; j < i; ++j) {
        const Vec3d pj = s.lidars[j].T_vehicle_lidar.translation();
        CHECK((pi - pj).norm() > 0.2);
      }
    }
  }
}

TEST_CASE("pair truth follows from the mounts; special rigs are what they say", "[sim][scenario]") {
  const ScenarioSpec s = *scenario("64-32");
  const PairTruth p = pair_truths(s).at(0);
  // A point of the target frame, seen from the vehicle through either path.
  const Vec3d x(3.0, -1.0, 0.5);
  const Vec3d via_pair = s.lidars[0].T_vehicle_lidar * (p.T_base_target * x);
  const Vec3d direct = s.lidars[1].T_vehicle_lidar * x;
  CHECK((via_pair - direct).norm() < 1e-12);
  CHECK(p.time_offset_s == 0.0);

  // pitched-90: the target's spin axis lies horizontal.
  const ScenarioSpec pitched = *scenario("pitched-90");
  const Vec3d spin_axis = pitched.lidars[1].T_vehicle_lidar.linear() * Vec3d::UnitZ();
  CHECK(std::abs(spin_axis.z()) < 0.1);
  // upside-down: the target's z axis points down.
  const ScenarioSpec upside = *scenario("upside-down");
  CHECK((upside.lidars[1].T_vehicle_lidar.linear() * Vec3d::UnitZ()).z() < -0.99);
  // side-bpearl: the Bpearl's hemisphere (its +z) looks sideways, to the left.
  const ScenarioSpec side = *scenario("side-bpearl");
  CHECK((side.lidars[1].T_vehicle_lidar.linear() * Vec3d::UnitZ()).y() > 0.99);
  // ring-5x16: five VLP-16, the four corner units yawed into four different quadrants.
  const ScenarioSpec ring = *scenario("ring-5x16");
  REQUIRE(ring.lidars.size() == 5);
  std::vector<int> quadrant;
  for (std::size_t i = 1; i < 5; ++i) {
    CHECK(ring.lidars[i].model == "VLP-16");
    const Vec3d x_axis = ring.lidars[i].T_vehicle_lidar.linear() * Vec3d::UnitX();
    quadrant.push_back((x_axis.x() > 0 ? 1 : 0) + (x_axis.y() > 0 ? 2 : 0));
  }
  std::sort(quadrant.begin(), quadrant.end());
  CHECK(quadrant == std::vector<int>{0, 1, 2, 3});
  CHECK(scenario("highway")->scene == SceneKind::highway);
  CHECK(scenario("tunnel")->scene == SceneKind::tunnel);
  CHECK(scenario("flicar-lift")->motion.lift_amplitude > 0.0);
}

TEST_CASE("clock offsets: offset-50ms, per-LiDAR setter and the option for any scenario",
          "[sim][scenario]") {
  const ScenarioSpec off = *scenario("offset-50ms");
  const PairTruth p = pair_truths(off).at(0);
  CHECK(p.time_offset_s == Approx(0.05));
  CHECK(p.T_base_target.isApprox(pair_truths(*scenario("64-32")).at(0).T_base_target));

  ScenarioSpec s = *scenario("32-avia");
  CHECK(set_clock_offset(s, "avia", -0.02));
  CHECK_FALSE(set_clock_offset(s, "nope", 1.0));
  CHECK(pair_truths(s).at(0).time_offset_s == Approx(-0.02));
  CHECK(set_clock_offset(s, s.lidars[0].name, 0.01));  // base clock moves too
  CHECK(pair_truths(s).at(0).time_offset_s == Approx(-0.03));

  // Through the options: every non-base LiDAR, visible in the frame timestamps.
  SimulationOptions o;
  o.seconds = 1.0;
  o.target_clock_offset_s = 0.07;
  o.decimation = 64;
  o.keep_frames = false;
  Simulator a, b;
  REQUIRE(a.init(*scenario("64-32"), o).ok());
  o.target_clock_offset_s.reset();
  REQUIRE(b.init(*scenario("64-32"), o).ok());
  CHECK(a.metadata().pairs.at(0).time_offset_s == Approx(0.07));
  CHECK(a.frame_timestamp(1, 3) == Approx(b.frame_timestamp(1, 3) - 0.07).margin(1e-12));
  CHECK(a.frame_timestamp(0, 3) == b.frame_timestamp(0, 3));
}

TEST_CASE("invalid options and scenarios come back as a status", "[sim][scenario]") {
  SimulationOptions o;
  o.seconds = -1.0;
  SimulationResult r = simulate(*scenario("64-32"), o);
  CHECK(r.status == SimStatus::invalid_options);
  CHECK_FALSE(r.reason.empty());
  o.seconds = 0.05;  // less than one 10 Hz frame
  CHECK(simulate(*scenario("64-32"), o).status == SimStatus::invalid_options);
  o.seconds = 1.0;
  ScenarioSpec bad = *scenario("64-32");
  bad.lidars[1].model = "NoSuchLidar";
  r = simulate(bad, o);
  CHECK(r.status == SimStatus::invalid_scenario);
  CHECK(r.reason.find("NoSuchLidar") != std::string::npos);
  bad = *scenario("64-32");
  bad.lidars[1].T_vehicle_lidar.translation() = Vec3d(1.0, 0.0, 1.0);  // inside the cabin
  CHECK(simulate(bad, o).status == SimStatus::invalid_scenario);
}
