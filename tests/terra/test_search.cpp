#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "terra/lattice.hpp"
#include "terra/random_rotation.hpp"
#include "terra/search.hpp"
#include "terra_test_util.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"

using terra_test::kDeg;

namespace {

/// The same cloud seen from a LiDAR turned by R_base_target: p_target = R^T p_base.
std::vector<ulc::Vec3d> turned(const std::vector<ulc::Vec3d>& cloud, const ulc::Mat3d& R) {
  std::vector<ulc::Vec3d> out;
  for (const auto& p : cloud) out.push_back(R.transpose() * p);
  return out;
}

}  // namespace

TEST_CASE("search finds known rotations of the scene, large ones included", "[search]") {
  const terra::Lattice lattice(10000);
  const auto cloud = terra_test::scan(ulc::Mat3d::Identity());
  const std::vector<ulc::Mat3d> truths = {
      ulc::so3_exp(ulc::Vec3d(1, 2, 3).normalized() * 90.0 * kDeg),
      ulc::so3_exp(ulc::Vec3d(-2, 1, 0.5).normalized() * 170.0 * kDeg),
      ulc::Mat3d::Identity(),
  };
  for (const auto& R_gt : truths) {
    const auto result = terra::estimate_rotation(lattice, cloud, turned(cloud, R_gt));
    const double error_deg = ulc::rotation_error_rad(R_gt, result.rotation) / kDeg;
    INFO("truth angle " << ulc::rotation_error_rad(ulc::Mat3d::Identity(), R_gt) / kDeg
                        << " deg, error " << error_deg << " deg, reason: " << result.reason);
    REQUIRE(result.ok());
    CHECK(error_deg < 2.0);
    CHECK(result.stats.coarse.rotations == 413 * 36);
    CHECK(result.seeds.size() == 10);
    CHECK(result.refined.size() == 10);
    CHECK(result.mask_count > 0);
    // The answer is the best refined seed, and refinement never makes a seed worse.
    // Every seed and every refined rotation keeps the minimum overlap (min_overlap_ratio).
    CHECK(result.stats.min_mask_count ==
          std::size_t(std::ceil(0.2 * double(result.stats.max_mask_count))));
    for (std::size_t s = 0; s < result.seeds.size(); ++s) {
      CHECK(result.distance <= result.refined[s].distance);
      CHECK(result.refined[s].distance <= result.seeds[s].distance);
      CHECK(result.seeds[s].mask_count >= result.stats.min_mask_count);
      CHECK(result.refined[s].mask_count >= result.stats.min_mask_count);
    }
    CHECK(result.stats.cell_evaluations == result.stats.rotations() * result.stats.base_beyond_d1);
  }
}

TEST_CASE("search succeeds on a re-scanned, shifted target LiDAR", "[search]") {
  // A second LiDAR with its own scan pattern, turned and 0.4 m away: no exact match exists,
  // and a rotation initialisation succeeds below 10 deg (docs/design.md).
  const terra::Lattice lattice(10000);
  const auto base = terra_test::scan(ulc::Mat3d::Identity());
  terra::SplitMix64 rng(17);
  for (int t = 0; t < 2; ++t) {
    const ulc::Mat3d R_gt = terra::random_rotation(rng);
    const auto target = terra_test::scan(R_gt, ulc::Vec3d(0.3, -0.2, 0.2), 40, 900);
    const auto result = terra::estimate_rotation(lattice, base, target);
    const double error_deg = ulc::rotation_error_rad(R_gt, result.rotation) / kDeg;
    INFO("error " << error_deg << " deg");
    REQUIRE(result.ok());
    CHECK(error_deg < ulc::kRotationInitMaxRotationDeg);
  }
}
