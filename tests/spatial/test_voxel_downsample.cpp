#include <tbb/task_arena.h>
#include <Eigen/Core>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdint>
#include <limits>
#include <map>
#include <vector>

#include "spatial_test_util.hpp"
#include "ulc/core/cloud.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace {

struct TimedPoint {
  double x, y, z;
  float intensity;
  double time;
};

}  // namespace

TEST_CASE("voxel downsample: centroids, order and skipped points by hand", "[voxel]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<TimedPoint> cloud = {
      {0.25, 0.25, 0.25, 10.f, 0.01},  // voxel (0,0,0)
      {-0.5, 0.5, 0.5, 1.f, 0.02},     // voxel (-1,0,0)
      {0.75, 0.75, 0.75, 20.f, 0.03},  // voxel (0,0,0)
      {nan, 0.0, 0.0, 5.f, 0.04},      // skipped
      {-0.25, 0.25, 0.75, 3.f, 0.06},  // voxel (-1,0,0)
      {1e12, 0.0, 0.0, 5.f, 0.05},     // skipped: beyond int32 voxels
      {5.5, 5.5, 5.5, 7.f, 0.07},      // voxel (5,5,5)
  };
  const auto result = ulc::voxel_downsample(cloud, 1.0);
  REQUIRE(result.ok());
  CHECK(result.skipped == 2);
  const auto& out = result.cloud;
  REQUIRE(out.size() == 3);
  CHECK(out.points[0] == Eigen::Vector3d(0.5, 0.5, 0.5));
  CHECK(out.points[1] == Eigen::Vector3d(-0.375, 0.375, 0.625));
  CHECK(out.points[2] == Eigen::Vector3d(5.5, 5.5, 5.5));
  CHECK(result.count == std::vector<std::uint32_t>{2, 2, 1});
  REQUIRE(out.has_intensities());
  CHECK(out.intensities[0] == 15.0);
  CHECK(out.intensities[1] == 2.0);
  REQUIRE(out.has_times());
  CHECK(out.times[0] == Approx(0.02));
  CHECK(out.times[1] == Approx(0.04));
  CHECK(out.times[2] == 0.07);
}

TEST_CASE("voxel downsample: plain points carry no intensity or time", "[voxel]") {
  const std::vector<Eigen::Vector3f> cloud = {{0.1f, 0.1f, 0.1f}, {0.3f, 0.3f, 0.3f}};
  const auto result = ulc::voxel_downsample(cloud, 0.5);
  REQUIRE(result.ok());
  REQUIRE(result.cloud.size() == 1);
  CHECK(result.cloud.points[0].x() == Approx(0.2f));
  CHECK_FALSE(result.cloud.has_intensities());
  CHECK_FALSE(result.cloud.has_times());
}

TEST_CASE("voxel downsample: bad voxel size and empty cloud", "[voxel]") {
  const std::vector<Eigen::Vector3d> cloud = {{1, 2, 3}};
  for (double size : {0.0, -1.0, std::numeric_limits<double>::infinity(),
                      std::numeric_limits<double>::quiet_NaN()}) {
    const auto result = ulc::voxel_downsample(cloud, size);
    CHECK(result.status == ulc::VoxelDownsampleStatus::invalid_voxel_size);
    CHECK(result.cloud.empty());
  }
  const auto empty = ulc::voxel_downsample(std::vector<Eigen::Vector3d>{}, 0.1);
  CHECK(empty.ok());
  CHECK(empty.cloud.empty());
  CHECK(empty.skipped == 0);
}

TEMPLATE_TEST_CASE("voxel downsample equals an independent computation, 1 and 2 threads",
                   "[voxel][threads]", float, double) {
  using S = TestType;
  auto cloud = spatial_test::random_cloud<S>(60000, S(20), 61);
  cloud[17] = ulc::Vec3<S>(std::numeric_limits<S>::quiet_NaN(), 0, 0);
  const double size = 0.7;

  // Independent: an ordered std::map, first index per voxel, sums in input order.
  struct Acc {
    std::size_t first;
    ulc::Vec3<double> sum;
    std::uint32_t count;
  };
  std::map<ulc::VoxelKey, Acc> voxels;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto key = ulc::make_voxel_key(cloud[i], size);
    if (!key) continue;
    auto it = voxels.find(*key);
    if (it == voxels.end()) it = voxels.emplace(*key, Acc{i, ulc::Vec3<double>::Zero(), 0}).first;
    it->second.sum += cloud[i].template cast<double>();
    ++it->second.count;
  }
  std::vector<Acc> expected;
  for (const auto& kv : voxels) expected.push_back(kv.second);
  std::sort(expected.begin(), expected.end(),
            [](const Acc& a, const Acc& b) { return a.first < b.first; });

  auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    return arena.execute([&] { return ulc::voxel_downsample(cloud, size); });
  };
  const auto one = run(1);
  const auto two = run(2);
  REQUIRE(one.ok());
  CHECK(one.skipped == 1);
  REQUIRE(one.cloud.size() == expected.size());
  for (std::size_t v = 0; v < expected.size(); ++v) {
    const ulc::Vec3<S> centroid =
        (expected[v].sum / static_cast<double>(expected[v].count)).template cast<S>();
    CHECK(one.cloud.points[v] == centroid);
    CHECK(one.count[v] == expected[v].count);
  }
  CHECK(two.cloud.points == one.cloud.points);
  CHECK(two.count == one.count);
  CHECK(two.skipped == one.skipped);
}
