// The ring gap (terra/ring_gap.hpp) on the ray-cast street of terra_test_util.hpp, whose scans
// space their beams evenly over 40 deg, and on a cloud of continuous elevations.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "terra/random_rotation.hpp"
#include "terra/ring_gap.hpp"
#include "terra_test_util.hpp"

using terra_test::kDeg;

TEST_CASE("the ring gap of a spinning scan is its beams' spacing", "[terra][ring_gap]") {
  for (const std::size_t beams : {8, 16, 32, 64}) {
    const auto scan = terra_test::scan(ulc::Mat3d::Identity(), ulc::Vec3d::Zero(), beams, 720);
    INFO(beams << " beams");
    // Within two bins of 0.05 deg (a ring's elevation falls on a bin's edge or inside one).
    CHECK(terra::ring_gap_deg(scan) == Approx(40.0 / double(beams - 1)).margin(0.1));
  }
}

TEST_CASE("continuous elevations have no ring gap", "[terra][ring_gap]") {
  terra::SplitMix64 rng(3);
  std::vector<ulc::Vec3d> cloud;
  for (int i = 0; i < 20000; ++i) {
    const double elevation = (-20.0 + 40.0 * rng.uniform()) * kDeg;
    const double azimuth = 2.0 * M_PI * rng.uniform();
    cloud.push_back(20.0 * ulc::Vec3d(std::cos(elevation) * std::cos(azimuth),
                                      std::cos(elevation) * std::sin(azimuth),
                                      std::sin(elevation)));
  }
  CHECK(terra::ring_gap_deg(cloud) == 0.0);
}

TEST_CASE("the ring gap ignores near, non-finite and absent points", "[terra][ring_gap]") {
  CHECK(terra::ring_gap_deg(std::vector<ulc::Vec3d>{}) == 0.0);
  auto scan = terra_test::scan(ulc::Mat3d::Identity(), ulc::Vec3d::Zero(), 16, 720);
  const double gap = terra::ring_gap_deg(scan);
  for (int i = 0; i < 500; ++i) {
    scan.push_back(ulc::Vec3d(0.1 * i, 0.2, 0.3).normalized() * 2.0);  // within min_range
    scan.push_back(ulc::Vec3d(NAN, 1.0, 1.0));
  }
  CHECK(terra::ring_gap_deg(scan) == gap);
  terra::RingGapOptions bad;
  bad.bin_deg = 0.0;
  CHECK(terra::ring_gap_deg(scan, bad) == 0.0);
}
