// LocalMap: nearest-plane queries equal a brute-force search, density and extent stay bounded,
// planes are those of the surfaces, and the map is the same for 1 and 2 threads.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <cstring>
#include <random>
#include <vector>

#include "../registration/registration_test_util.hpp"
#include "odometry/local_map.hpp"

using namespace reg_test;

namespace {

std::vector<ulc::Vec3<float>> as_float(const std::vector<Vec3d>& p) {
  std::vector<ulc::Vec3<float>> out;
  for (const Vec3d& x : p) out.push_back(x.cast<float>());
  return out;
}

}  // namespace

TEST_CASE("local map: find_plane returns the nearest point with a plane, as brute force does",
          "[jeep][map]") {
  odometry::LocalMap<float> map;
  map.insert(as_float(courtyard(1, 4000, 0.01)), Vec3d::Zero());
  const auto points = map.points();
  const auto normals = map.normals();
  REQUIRE(points.size() == map.size());
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> x(-17, 17), y(-14, 14), z(-1, 7);
  std::size_t matched = 0;
  for (double gate : {0.3, 1.0, 2.5}) {
    for (int q = 0; q < 1500; ++q) {
      const Vec3d query(x(rng), y(rng), z(rng));
      double best = gate * gate;
      std::ptrdiff_t best_i = -1;
      for (std::size_t i = 0; i < points.size(); ++i) {
        if (normals[i].squaredNorm() == 0.0f) continue;
        const double d2 = (points[i].cast<double>() - query).squaredNorm();
        if (d2 < best) best = d2, best_i = static_cast<std::ptrdiff_t>(i);
      }
      ulc::PlaneMatch m;
      const bool found = map.find_plane(query, gate, m);
      INFO("gate " << gate << " query " << query.transpose());
      REQUIRE(found == (best_i >= 0));
      if (!found) continue;
      ++matched;
      CHECK((m.point - query).squaredNorm() == Approx(best).epsilon(1e-12));
      CHECK(m.normal.norm() == Approx(1.0).epsilon(1e-5));
    }
  }
  CHECK(matched > 1000);
}

TEST_CASE("local map: capped voxels, spaced points, and a parked sensor adds nothing",
          "[jeep][map]") {
  odometry::LocalMapOptions o;
  o.voxel_size = 1.0;
  o.max_points_per_voxel = 12;
  o.min_point_distance = 0.15;
  odometry::LocalMap<double> map(o);
  std::vector<Vec3d> scan = courtyard(3, 20000, 0.01);
  map.insert(scan, Vec3d::Zero());
  const std::size_t first = map.size();
  CHECK(first <= 12 * map.voxel_count());
  CHECK(first < scan.size() / 4);  // the cap binds
  map.insert(courtyard(4, 20000, 0.01), Vec3d::Zero());
  CHECK(map.size() <= 12 * map.voxel_count());
  const auto pts = map.points();
  // Points of one voxel are at least min_point_distance apart.
  std::size_t close_pairs = 0;
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = i + 1; j < std::min(pts.size(), i + 12); ++j)
      if (*ulc::make_voxel_key(pts[i], 1.0) == *ulc::make_voxel_key(pts[j], 1.0) &&
          (pts[i] - pts[j]).norm() < 0.15)
        ++close_pairs;
  CHECK(close_pairs == 0);
  // The same scan again, from the same place: nothing new fits.
  const std::size_t before = map.size();
  map.insert(scan, Vec3d::Zero());
  CHECK(map.size() == before);
}

TEST_CASE("local map: planes follow the surfaces", "[jeep][map]") {
  odometry::LocalMap<double> map;
  map.insert(courtyard(5, 6000, 0.005), Vec3d::Zero());
  const auto pts = map.points();
  const auto nrm = map.normals();
  std::size_t ground = 0, good = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    // Away from the walls and boxes, on the ground.
    if (std::abs(pts[i].z()) > 0.02 || std::abs(pts[i].x()) > 12 || std::abs(pts[i].y()) > 9 ||
        (pts[i] - Vec3d(5, 3, 0)).norm() < 4 || (pts[i] - Vec3d(-5, -3, 0)).norm() < 3)
      continue;
    ++ground;
    good += std::abs(nrm[i].z()) > 0.99 ? 1 : 0;
  }
  REQUIRE(ground > 100);
  CHECK(good == ground);
}

TEST_CASE("local map: voxels beyond max_distance from the sensor are dropped", "[jeep][map]") {
  odometry::LocalMapOptions o;
  o.max_distance = 40.0;
  o.prune_step = 5.0;
  odometry::LocalMap<float> map(o);
  map.insert(as_float(courtyard(1, 2000, 0.01)), Vec3d::Zero());
  const std::size_t here = map.size();
  // Drive 100 m east and see the same kind of courtyard there.
  const Isometry3d east = Isometry3d(Eigen::Translation3d(100, 0, 0));
  map.insert(as_float(transformed(courtyard(2, 2000, 0.01), east)), Vec3d(100, 0, 0));
  const auto pts = map.points();
  CHECK(pts.size() < here + 10);
  const double reach = 40.0 + std::sqrt(3.0) / 2;  // a voxel's centre within 40 m
  for (const auto& p : pts) CHECK((p.cast<double>() - Vec3d(100, 0, 0)).norm() <= reach);
  ulc::PlaneMatch m;
  CHECK_FALSE(map.find_plane(Vec3d(0, 0, 0), 1.0, m));
  CHECK(map.find_plane(Vec3d(100, 0, 0.1), 1.0, m));
}

TEST_CASE("local map: the same map for 1 and 2 threads", "[jeep][map][threads]") {
  auto build = [] {
    odometry::LocalMap<float> map;
    map.insert(as_float(courtyard(1, 5000, 0.01)), Vec3d::Zero());
    map.insert(as_float(courtyard(2, 5000, 0.01)), Vec3d::Zero());
    return std::make_pair(map.points(), map.normals());
  };
  tbb::task_arena one(1), two(2);
  const auto a = one.execute(build);
  const auto b = two.execute(build);
  REQUIRE(a.first.size() == b.first.size());
  CHECK(std::memcmp(a.first.data(), b.first.data(), a.first.size() * sizeof(a.first[0])) == 0);
  CHECK(std::memcmp(a.second.data(), b.second.data(), a.second.size() * sizeof(a.second[0])) == 0);
}
