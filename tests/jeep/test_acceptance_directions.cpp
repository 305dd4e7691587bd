// JEEP's acceptance judges the direction the maps agree on least (acceptance.hpp): two maps
// that share their ground but not their walls are refused even though most of their points
// agree, and two samplings of the same place are accepted. Off the ground: maps whose walls
// agree but whose ground mostly does not (a sparse unit's far ground between rings) are
// accepted, and maps that disagree on the ground's height altogether are not.
#include <catch2/catch.hpp>
#include <functional>
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

using jeep_test::kX;
using jeep_test::kY;
using jeep_test::kZ;

/// Height of the ground tile (i, j), i, j in 0..9 (4 m tiles).
using TileHeight = std::function<double(int, int)>;

/// A street corner: 40 x 40 m of ground, a wall facing x at x = wall_x and one facing y at
/// y = wall_y (4 m high); a 6 m patch of each wall (centred on the other axis' zero) stays at
/// x = 10 / y = 8 whatever the rest does. The ground is flat unless `tile_height` says so.
Points corner(double wall_x, double wall_y, double phase, std::mt19937& rng,
              const TileHeight& tile_height = {}) {
  Points p;
  const double step = 0.2;
  if (tile_height) {
    for (int i = 0; i < 10; ++i)
      for (int j = 0; j < 10; ++j)
        add_rectangle(p, {-20.0 + 4 * i, -20.0 + 4 * j, tile_height(i, j)}, kX, 4, kY, 4, step,
                      phase, rng);
  } else {
    add_rectangle(p, {-20, -20, 0}, kX, 40, kY, 40, step, phase, rng);
  }
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
      << ", off the ground " << r.off_ground_overlap << " (ground share " << r.ground_share
      << "), condition " << r.condition;
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
  // The ground is the dominant plane, and fewer directions cannot have a weaker one.
  CHECK(r.ground_share > 0.5);
  CHECK(r.off_ground_overlap >= r.directional_overlap - 1e-9);
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
  // A plain-overlap rule (overlap >= 0.6, condition >= min_condition) would have accepted.
  CHECK(r.overlap > 0.6);
  CHECK(r.condition >= jeep::AcceptanceOptions{}.min_condition);
  CHECK(r.off_ground_overlap < jeep::AcceptanceOptions{}.min_off_ground_overlap);
  CHECK_FALSE(r.accepted);
  CHECK(std::string(r.reason).find("some directions only") != std::string::npos);
}

TEST_CASE("acceptance looks past a ground the two maps see differently", "[jeep][acceptance]") {
  std::mt19937 rng(13);
  const Points a = corner(10, 8, 0.0, rng);
  // The same walls; about 85 % of the ground tiles 20-40 cm up or down (outside the inlier
  // distance, inside the gate), as a sparse unit's far ground lies off a denser one's extrapolated
  // planes.
  std::mt19937 tiles(5);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<double> height(100);
  for (double& h : height) {
    const double lift = 0.2 + 0.2 * u01(tiles);
    h = u01(tiles) < 0.85 ? (u01(tiles) < 0.5 ? -lift : lift) : 0.0;
  }
  const Points b = corner(10, 8, 0.1, rng, [&](int i, int j) { return height[10 * i + j]; });
  const auto r = judge(a, b);
  INFO(evidence(r));
  const jeep::AcceptanceOptions rule;
  // Over all six directions the weakest (the height) is mostly disagreement; off the ground
  // every wall agrees.
  CHECK(r.directional_overlap < rule.min_off_ground_overlap);
  CHECK(r.directional_overlap >= rule.min_directional_overlap);
  CHECK(r.off_ground_overlap > 0.8);
  CHECK(r.accepted);
}

TEST_CASE("acceptance refuses maps that disagree on the ground's height", "[jeep][acceptance]") {
  std::mt19937 rng(17);
  const Points a = corner(10, 8, 0.0, rng);
  // Every wall agrees, the whole ground is 30 cm higher: the extrinsic's height is wrong.
  const Points b = corner(10, 8, 0.1, rng, [](int, int) { return 0.3; });
  const auto r = judge(a, b);
  INFO(evidence(r));
  CHECK(r.off_ground_overlap > 0.8);
  CHECK(r.directional_overlap < jeep::AcceptanceOptions{}.min_directional_overlap);
  CHECK_FALSE(r.accepted);
  CHECK(std::string(r.reason).find("ground itself") != std::string::npos);
}
