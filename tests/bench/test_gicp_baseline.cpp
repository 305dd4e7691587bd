// The GICP refinement baseline of bench_jeep (bench/gicp_baseline.hpp) on the synthetic room of
// room_scene.hpp, the source placed by a known pose. GICP must recover the pose from a small start
// and from the refinement table's 5 deg / 2 m one, give the same answer twice, and refuse too few
// points.
#include <catch2/catch.hpp>

#include "../../bench/gicp_baseline.hpp"
#include "room_scene.hpp"
#include "ulc/core/pose_error.hpp"

namespace {

using room_scene::pose;
using room_scene::Scene;
using ulc::Isometry3d;

}  // namespace

TEST_CASE("GICP recovers a small pose between two samplings of a room", "[bench][gicp]") {
  const Scene s;
  const auto r = gicp_baseline::gicp(s.source, s.target, Isometry3d::Identity());
  const auto e = ulc::pose_error(s.truth, r.pose);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m, " << r.iterations
                << " iterations, " << r.correspondences << " matches");
  CHECK(r.converged);
  CHECK(e.rotation_deg < 0.05);
  CHECK(e.translation_m < 0.005);
  CHECK(r.correspondences > s.source.size() / 2);
}

TEST_CASE("GICP recovers the pose from the refinement table's 5 deg / 2 m start", "[bench][gicp]") {
  const Scene s;
  const Isometry3d start = pose(5.0, {-2, 1, 1}, {1.6, 1.0, 0.6}) * s.truth;
  REQUIRE(ulc::pose_error(s.truth, start).translation_m > 1.9);
  const auto r = gicp_baseline::gicp(s.source, s.target, start);
  const auto e = ulc::pose_error(s.truth, r.pose);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m, " << r.iterations
                << " iterations");
  CHECK(r.converged);
  CHECK(e.rotation_deg < 0.05);
  CHECK(e.translation_m < 0.005);
}

TEST_CASE("GICP gives the same pose twice", "[bench][gicp]") {
  const Scene s;
  const Isometry3d start = pose(2.0, {0, 0, 1}, {0.5, 0, 0});
  const auto a = gicp_baseline::gicp(s.source, s.target, start);
  const auto b = gicp_baseline::gicp(s.source, s.target, start);
  CHECK(a.pose.matrix() == b.pose.matrix());
  CHECK(a.iterations == b.iterations);
}

TEST_CASE("GICP refuses clouds with fewer points than the correspondences it needs",
          "[bench][gicp]") {
  const Scene s;
  const gicp_baseline::Points few(s.source.begin(), s.source.begin() + 10);
  const auto r = gicp_baseline::gicp(few, s.target, Isometry3d::Identity());
  CHECK_FALSE(r.converged);
  CHECK(r.iterations == 0);
}
