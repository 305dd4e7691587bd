#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "terra/random_rotation.hpp"
#include "terra/rotation_grid.hpp"
#include "terra_test_util.hpp"
#include "ulc/core/pose_error.hpp"

using terra_test::kDeg;

namespace {

/// Largest distance from `samples` random rotations to their nearest grid rotation, in degrees.
double covering_radius_deg(const std::vector<ulc::Mat3d>& grid, std::size_t samples) {
  terra::SplitMix64 rng(99);
  double worst = 0;
  for (std::size_t s = 0; s < samples; ++s) {
    const ulc::Mat3d R = terra::random_rotation(rng);
    double best = 10.0;
    for (const auto& G : grid) best = std::min(best, ulc::rotation_error_rad(G, R));
    worst = std::max(worst, best);
  }
  return worst / kDeg;
}

}  // namespace

TEST_CASE("the SO(3) grid reaches every rotation within one stride", "[grid]") {
  for (double stride : {30.0, 10.0}) {
    const auto grid = terra::so3_grid(stride * kDeg);
    INFO("stride " << stride << " deg, " << grid.size() << " rotations");
    for (const auto& R : grid) {
      CHECK((R.transpose() * R - ulc::Mat3d::Identity()).norm() < 1e-12);
      CHECK(R.determinant() == Approx(1.0));
    }
    const double radius = covering_radius_deg(grid, stride > 20 ? 3000 : 600);
    INFO("covering radius " << radius << " deg");
    CHECK(radius < stride);
  }
  // Far fewer rotations than the 36 x 19 x 36 = 24624 of the plain Euler grid at 10 deg.
  CHECK(terra::so3_grid(10.0 * kDeg).size() == 413 * 36);
  CHECK(terra::so3_grid(0.0).empty());
  CHECK(terra::so3_grid(-1.0).empty());
}

TEST_CASE("descent moves are the 26 rotations of one step about the grid axes", "[grid]") {
  const auto moves = terra::descent_moves(1.0 * kDeg);
  REQUIRE(moves.size() == 26);
  std::size_t one = 0, two = 0, three = 0;
  for (const auto& M : moves) {
    const double angle = ulc::rotation_error_rad(ulc::Mat3d::Identity(), M) / kDeg;
    one += std::fabs(angle - 1.0) < 1e-9;
    two += std::fabs(angle - std::sqrt(2.0)) < 1e-9;
    three += std::fabs(angle - std::sqrt(3.0)) < 1e-9;
  }
  CHECK(one == 6);
  CHECK(two == 12);
  CHECK(three == 8);
}
