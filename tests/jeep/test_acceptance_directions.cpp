// JEEP's acceptance judges the direction the maps agree on least (acceptance.hpp): two maps
// that share their ground but not their walls are refused even though most of their points
// agree, and two samplings of the same place are accepted.
#include <catch2/catch.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "jeep/acceptance.hpp"
#include "jeep/map_registration.hpp"
#include "surface_samples.hpp"

namespace {

using jeep_test::add_rectangle;
using Points = jeep_test::SurfacePoints;

const ulc::Vec3d kX = ulc::Vec3d::UnitX(), kY = ulc::Vec3d::UnitY(), kZ = ulc::Vec3d::UnitZ();

/// A street corner: 40 x 40 m of ground, a wall facing x at x = wall_x and one facing y at
/// y = wall_y (4 m high); a 6 m patch of each wall (centred on the other axis' zero) stays at
/// x = 10 / y = 8 whatever the rest does.
Points corner(double wall_x, double wall_y, double phase, std::mt19937& rng) {
  Points p;
  const double step = 0.2;
  add_rectangle(p, {-20, -20, 0}, kX, 40, kY, 40, step, phase, rng);
  add_rectangle(p, {wall_x, -20, 0}, kY, 17, kZ, 4, step, phase, rng);
  add_rectangle(p, {10, -3, 0}, kY, 6, kZ, 4, step, phase, rng);
  add_rectangle(p, {wall_x, 3, 0}, kY, 17, kZ, 4, step, phase, rng);
  add_rectangle(p, {-20, wall_y, 0}, kX, 17, kZ, 4, step, phase, rng);
  add_rectangle(p, {-3, 8, 0}, kX, 6, kZ, 4, step, phase, rng);
  add_rectangle(p, {3, wall_y, 0}, kX, 17, kZ, 4, step, phase, rng);
  return p;
}

jeep::AcceptanceReport judge(const Points& a, const Points& b) {
  const auto planes = jeep::default_map_registration();
  return jeep::assess(a, b, jeep::map_target(a, planes), planes, ulc::Isometry3d::Identity(),
                      jeep::AcceptanceOptions{});
}

/// The report's verdict and evidence, for a failing check's message.
std::string evidence(const jeep::AcceptanceReport& r) {
  std::ostringstream out;
  out << r.reason << "; overlap " << r.overlap << ", directional " << r.directional_overlap
      << ", condition " << r.condition;
  return out.str();
}

}  // namespace

TEST_CASE("acceptance accepts two samplings of one place", "[jeep][acceptance]") {
  std::mt19937 rng(7);
  const Points a = corner(10, 8, 0.0, rng);
  const Points b = corner(10, 8, 0.1, rng);
  const auto r = judge(a, b);
  INFO(evidence(r));
  CHECK(r.accepted);
  CHECK(r.overlap > 0.9);
  CHECK(r.directional_overlap > 0.8);
  CHECK(r.directional_overlap <= r.overlap + 1e-9);
}

TEST_CASE("acceptance refuses maps that agree on the ground but not on their walls",
          "[jeep][acceptance]") {
  std::mt19937 rng(11);
  const Points a = corner(10, 8, 0.0, rng);
  // The same ground, walls half a metre behind (inside the gate, far outside the inlier
  // distance) except for the two 6 m patches: most points agree, and the agreeing ones pin all
  // six directions (the patches), but along x and y most of the evidence disagrees.
  const Points b = corner(10.5, 8.5, 0.1, rng);
  const auto r = judge(a, b);
  INFO(evidence(r));
  // The former rule (overlap >= 0.6, condition >= min_condition) would have accepted.
  CHECK(r.overlap > 0.6);
  CHECK(r.condition >= jeep::AcceptanceOptions{}.min_condition);
  CHECK(r.directional_overlap < jeep::AcceptanceOptions{}.min_directional_overlap);
  CHECK_FALSE(r.accepted);
  CHECK(std::string(r.reason).find("some directions only") != std::string::npos);
}
