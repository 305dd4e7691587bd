#include <tbb/task_arena.h>
#include <Eigen/Core>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "terra/lattice.hpp"
#include "terra/profile.hpp"
#include "terra/random_rotation.hpp"
#include "terra/search.hpp"
#include "terra_test_util.hpp"
#include "ulc/core/pose_error.hpp"

using terra_test::kDeg;

TEST_CASE("search gives the same bits for 1 and 2 threads", "[search][threads]") {
  const terra::Lattice lattice(3000);
  const auto base = terra_test::scan(ulc::Mat3d::Identity());
  terra::SplitMix64 rng(23);
  const ulc::Mat3d R_gt = terra::random_rotation(rng);
  const auto target = terra_test::scan(R_gt, ulc::Vec3d(0.2, 0.1, 0.0));
  tbb::task_arena one(1), two(2);
  const auto r1 = one.execute([&] { return terra::estimate_rotation(lattice, base, target); });
  const auto r2 = two.execute([&] { return terra::estimate_rotation(lattice, base, target); });
  REQUIRE(r1.ok());
  REQUIRE(r2.ok());
  CHECK(r1.rotation == r2.rotation);
  CHECK(r1.distance == r2.distance);
  CHECK(r1.mask_count == r2.mask_count);
  CHECK(r1.stats.rotations() == r2.stats.rotations());
  REQUIRE(r1.refined.size() == r2.refined.size());
  for (std::size_t s = 0; s < r1.refined.size(); ++s) {
    CHECK(r1.seeds[s].rotation == r2.seeds[s].rotation);
    CHECK(r1.refined[s].rotation == r2.refined[s].rotation);
    CHECK(r1.refined[s].descent_steps == r2.refined[s].descent_steps);
  }
  // N = 3000 is coarse (3.7 deg cells) but the answer is still a successful initialisation.
  CHECK(ulc::rotation_error_rad(R_gt, r1.rotation) / kDeg < ulc::kRotationInitMaxRotationDeg);
}

TEST_CASE("clouds with only near points report no_overlap", "[search]") {
  // A closed 6 x 4 x 3 m room: every return is closer than d1 = 20 m, and closer than the
  // 5 m floor of the adaptive d1 rule (on by default).
  std::vector<ulc::Vec3d> room;
  for (const auto& d : terra_test::random_directions(20000, 3)) {
    double t = 1e9;
    const double half[3] = {3.0, 2.0, 1.5};
    for (int a = 0; a < 3; ++a)
      if (d[a] != 0.0) t = std::min(t, half[a] / std::fabs(d[a]));
    room.push_back(d * t);
  }
  const terra::Lattice lattice(2000);
  const auto result = terra::estimate_rotation(lattice, room, room);
  CHECK(result.status == terra::SearchStatus::no_overlap);
  CHECK(std::string(terra::to_string(result.status)) == "no_overlap");
  CHECK(result.reason.find("d1") != std::string::npos);
  CHECK(result.stats.base_beyond_d1 == 0);

  // Let the adaptive rule go below its 5 m floor and the room overlaps with itself.
  terra::SearchParams near;
  near.adaptive_d1.floor_m = 0.5;
  const auto adapted = terra::estimate_rotation(lattice, room, room, near);
  CHECK(adapted.ok());
  CHECK(adapted.stats.d1_adapted);
  CHECK(adapted.stats.d1_used < 3.0);
}

TEST_CASE("far clouds that never agree within d2 report no_overlap", "[search]") {
  // Both clouds are far, but every base range is 30 m and every target range 60 m: no
  // rotation brings |F1 - F2| within d2 = 5 m, so every mask is empty.
  std::vector<ulc::Vec3d> base, target;
  for (const auto& d : terra_test::random_directions(5000, 5)) {
    base.push_back(d * 30.0);
    target.push_back(d * 60.0);
  }
  const terra::Lattice lattice(500);
  terra::SearchParams p;
  p.coarse_stride_deg = 30.0;  // keep the exhaustive failure quick
  const auto result = terra::estimate_rotation(lattice, base, target, p);
  CHECK(result.status == terra::SearchStatus::no_overlap);
  CHECK(result.reason.find("non-empty eq:mask") != std::string::npos);
  CHECK(!result.stats.overlap_found_at_stage0);
  CHECK(result.stats.rotations() > 0);
}

TEST_CASE("invalid inputs are reported, not crashed on", "[search]") {
  const terra::Lattice lattice(500);
  const std::vector<ulc::Vec3d> empty;
  std::vector<ulc::Vec3d> cloud;
  for (const auto& d : terra_test::random_directions(2000, 9)) cloud.push_back(d * 30.0);
  auto r = terra::estimate_rotation(lattice, empty, cloud);
  CHECK(r.status == terra::SearchStatus::invalid_input);
  CHECK(r.reason == "base cloud is empty");
  r = terra::estimate_rotation(lattice, cloud, empty);
  CHECK(r.reason == "target cloud is empty");
  r = terra::estimate_rotation(terra::Lattice(), cloud, cloud);
  CHECK(r.status == terra::SearchStatus::invalid_input);

  auto bad = [&](auto change) {
    terra::SearchParams p;
    change(p);
    const auto result = terra::estimate_rotation(lattice, cloud, cloud, p);
    INFO("reason: " << result.reason);
    CHECK(result.status == terra::SearchStatus::invalid_input);
    CHECK(!result.reason.empty());
  };
  bad([](terra::SearchParams& p) { p.top_k = 0; });
  bad([](terra::SearchParams& p) { p.coarse_stride_deg = 0.0; });
  bad([](terra::SearchParams& p) { p.fine_stride_deg = -1.0; });
  bad([](terra::SearchParams& p) { p.overlap_stride_deg = 400.0; });
  bad([](terra::SearchParams& p) { p.distance.d1 = -1.0; });
  bad([](terra::SearchParams& p) { p.distance.d2 = std::nan(""); });
  bad([](terra::SearchParams& p) { p.distance.alpha = -2.0; });
  bad([](terra::SearchParams& p) { p.min_overlap_ratio = 1.5; });
  bad([](terra::SearchParams& p) { p.adaptive_d1.percentile = 2.0; });
  bad([](terra::SearchParams& p) { p.adaptive_d1.floor_m = -1.0; });
  // Points all closer than min_range leave nothing to describe.
  const std::vector<ulc::Vec3d> body = {{0.1, 0, 0}, {0, 0.2, 0}};
  r = terra::estimate_rotation(lattice, body, cloud);
  CHECK(r.status == terra::SearchStatus::invalid_input);
  CHECK(r.reason.find("usable range") != std::string::npos);
  // The overload that builds its own lattice.
  terra::SearchParams tiny;
  tiny.lattice_size = 1;
  CHECK(terra::estimate_rotation(cloud, cloud, tiny).status == terra::SearchStatus::invalid_input);
  tiny.lattice_size = 300;
  CHECK(terra::estimate_rotation(cloud, cloud, tiny).ok());
  // Descriptors of another lattice.
  const auto other = terra::make_descriptor(terra::Lattice(400), cloud);
  r = terra::search_rotation(lattice, other, other);
  CHECK(r.status == terra::SearchStatus::invalid_input);
}

TEST_CASE("adaptive d1 lowers d1 for short-range clouds", "[search]") {
  // A short-range scene: the room of the no_overlap test, scaled so ranges reach ~12 m.
  std::vector<ulc::Vec3d> room;
  for (const auto& d : terra_test::random_directions(30000, 13)) {
    double t = 1e9;
    const double half[3] = {12.0, 7.0, 3.0};
    const double shift[3] = {2.0, -1.5, 0.5};  // off-centre: no symmetric twin
    for (int a = 0; a < 3; ++a)
      if (d[a] != 0.0) t = std::min(t, ((d[a] > 0 ? half[a] : -half[a]) - shift[a]) / d[a]);
    room.push_back(d * t);
  }
  const ulc::Mat3d R_gt = ulc::so3_exp(ulc::Vec3d(0.3, 0.5, -1).normalized() * 40.0 * kDeg);
  std::vector<ulc::Vec3d> target;
  for (const auto& p : room) target.push_back(R_gt.transpose() * p);
  const terra::Lattice lattice(3000);
  terra::SearchParams p;
  p.adaptive_d1.enabled = false;  // the paper's fixed d1 = 20 m: nothing to compare
  CHECK(terra::estimate_rotation(lattice, room, target, p).status ==
        terra::SearchStatus::no_overlap);
  p.adaptive_d1.enabled = true;  // the default
  const auto r = terra::estimate_rotation(lattice, room, target, p);
  REQUIRE(r.ok());
  CHECK(r.stats.d1_adapted);
  CHECK(r.stats.d1_used < 12.0);
  CHECK(r.stats.d1_used >= 5.0);  // the floor
  CHECK(ulc::rotation_error_rad(R_gt, r.rotation) / kDeg < 3.0);
}

TEST_CASE("progress is reported from 0 to 1 on the calling thread", "[search]") {
  const terra::Lattice lattice(1000);
  const auto cloud = terra_test::scan(ulc::Mat3d::Identity());
  std::vector<double> seen;
  terra::SearchParams p;
  p.progress = [&](double f) { seen.push_back(f); };
  REQUIRE(terra::estimate_rotation(lattice, cloud, cloud, p).ok());
  REQUIRE(seen.size() >= 2);
  CHECK(seen.front() == 0.0);
  CHECK(seen.back() == 1.0);
  CHECK(std::is_sorted(seen.begin(), seen.end()));
}

TEST_CASE("float and double clouds give the same answer; profile_case is seeded", "[search]") {
  const terra::Lattice lattice(3000);
  const auto cloud = terra_test::scan(ulc::Mat3d::Identity());
  std::vector<Eigen::Vector3f> cloud_f;
  for (const auto& p : cloud) cloud_f.push_back(p.cast<float>());
  const auto a = terra::profile_case(lattice, cloud, cloud, ulc::Mat3d::Identity(), 5);
  const auto b = terra::profile_case(lattice, cloud_f, cloud_f, ulc::Mat3d::Identity(), 5);
  const auto again = terra::profile_case(lattice, cloud, cloud, ulc::Mat3d::Identity(), 5);
  const auto other = terra::profile_case(lattice, cloud, cloud, ulc::Mat3d::Identity(), 6);
  REQUIRE(a.result.ok());
  REQUIRE(b.result.ok());
  CHECK(a.applied == b.applied);
  CHECK(a.result.rotation == again.result.rotation);
  CHECK(!(a.applied == other.applied));
  CHECK(a.error_deg < 3.0);
  CHECK(b.error_deg < 3.0);
  CHECK(other.error_deg < 3.0);
  CHECK(ulc::rotation_error_rad(a.result.rotation, b.result.rotation) / kDeg < 3.0);
  CHECK(a.error_deg == Approx(ulc::rotation_error_rad(a.truth, a.result.rotation) / kDeg));
}
