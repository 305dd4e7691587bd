// Plane extraction's grouping: the window's points placed, sorted into their root voxels (each
// voxel's points ascending, voxels in order of their first point), and every plane's frame
// clusters holding exactly the plane's points.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "hots/plane_extraction.hpp"
#include "hots_test_util.hpp"

using namespace hots;
using namespace hots_test;

namespace {

struct RoomScan {
  std::vector<Isometry3d> poses;
  std::vector<std::vector<Vec3d>> frames;
  std::vector<const std::vector<Vec3d>*> clouds;
};

RoomScan room_scan() {
  RoomScan r;
  r.poses = room_path(4, 0.5);
  r.frames = room_frames(r.poses, 0.25, 0.01, 3);
  // Points no voxel can hold: skipped, never grouped.
  r.frames[1].push_back(Vec3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  r.frames[2].push_back(Vec3d(1e30, 0.0, 0.0));
  for (const auto& f : r.frames) r.clouds.push_back(&f);
  return r;
}

}  // namespace

TEST_CASE("plane extraction groups each root voxel's points in input order", "[hots][planes]") {
  const RoomScan r = room_scan();
  PlaneExtractionOptions options;
  const auto window = plane_detail::place_points(r.clouds, r.poses, options);
  std::size_t finite = 0;
  for (const auto& f : r.frames) finite += f.size();
  finite -= 2;
  REQUIRE(window.points.size() == finite);
  REQUIRE(window.keys.size() == finite);
  for (std::size_t i = 0; i < window.points.size(); ++i) {
    const auto& p = window.points[i];
    CHECK((r.poses[p.frame] * p.body - p.world).norm() < 1e-9);
    CHECK(window.keys[i] == *ulc::make_voxel_key(p.world, options.voxel_size));
  }

  const auto roots = plane_detail::group_by_voxel(window);
  REQUIRE(roots.start.size() == roots.keys.size() + 1);
  REQUIRE(roots.start.back() == finite);
  REQUIRE(roots.members.size() == finite);
  std::vector<int> seen(finite, 0);
  std::uint32_t previous_first = 0;
  for (std::size_t v = 0; v < roots.keys.size(); ++v) {
    REQUIRE(roots.start[v] < roots.start[v + 1]);  // no empty voxel
    const std::uint32_t first = roots.members[roots.start[v]];
    if (v > 0) CHECK(first > previous_first);  // voxels in order of their first point
    previous_first = first;
    for (std::uint32_t k = roots.start[v]; k < roots.start[v + 1]; ++k) {
      const std::uint32_t i = roots.members[k];
      if (k > roots.start[v]) CHECK(i > roots.members[k - 1]);
      CHECK(window.keys[i] == roots.keys[v]);
      ++seen[i];
    }
  }
  for (const int s : seen) CHECK(s == 1);
}

TEST_CASE("every extracted plane's frame clusters hold its points", "[hots][planes]") {
  const RoomScan r = room_scan();
  PlaneExtractionOptions options;
  const auto planes = extract_planes(r.clouds, r.poses, options);
  REQUIRE(planes.size() > 20);
  for (const Plane& plane : planes) {
    double clustered = 0.0;
    for (std::size_t k = 0; k < plane.frames.size(); ++k) {
      if (k > 0) CHECK(plane.frames[k].frame > plane.frames[k - 1].frame);
      clustered += plane.frames[k].cluster.count;
    }
    CHECK(clustered == static_cast<double>(plane.points));
    CHECK(plane.points >= options.min_points);
    CHECK(plane.frames.size() >= options.min_frames);
  }
}
