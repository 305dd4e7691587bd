#include <Eigen/Core>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <unordered_set>
#include <vector>

#include "ulc/core/voxel.hpp"

TEST_CASE("voxel keys floor towards minus infinity", "[voxel]") {
  const auto k = ulc::make_voxel_key(Eigen::Vector3d(-0.05, 0.05, -0.15), 0.1);
  REQUIRE(k);
  CHECK(k->x == -1);
  CHECK(k->y == 0);
  CHECK(k->z == -2);
  const auto kf = ulc::make_voxel_key(Eigen::Vector3f(-0.05f, 0.0f, -1e-7f), 0.1);
  REQUIRE(kf);
  CHECK(kf->x == -1);
  CHECK(kf->y == 0);
  CHECK(kf->z == -1);
  // Voxel 0 is [0, size): its lower bound is in, its upper bound is the next voxel.
  CHECK(ulc::make_voxel_key(Eigen::Vector3d(0.0, 0.5, 1.0), 0.5)->y == 1);
  CHECK(ulc::make_voxel_key(Eigen::Vector3d(0.0, 0.5, 1.0), 0.5)->z == 2);
  CHECK(ulc::make_voxel_key(Eigen::Vector3d(0.0, 0.5, 1.0), 0.5)->x == 0);
}

TEST_CASE("far, infinite and NaN coordinates make no key", "[voxel]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(1e12, 0, 0), 0.1));
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(0, -1e12, 0), 0.1));
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(0, 0, 1e30), 0.1));
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(nan, 0, 0), 0.1));
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(0, inf, 0), 0.1));
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(0, 0, -inf), 0.1));
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3f(std::numeric_limits<float>::max(), 0, 0), 1.0));
  // Bad voxel sizes make no key either.
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(1, 1, 1), 0.0));
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(1, 1, 1), -0.1));
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(1, 1, 1), nan));
  // The int32 edge: the last representable voxel is accepted, the next one is not.
  const auto edge = ulc::make_voxel_key(Eigen::Vector3d(2147483647.5, -2147483648.0, 0), 1.0);
  REQUIRE(edge);
  CHECK(edge->x == std::numeric_limits<std::int32_t>::max());
  CHECK(edge->y == std::numeric_limits<std::int32_t>::min());
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(2147483648.0, 0, 0), 1.0));
  CHECK_FALSE(ulc::make_voxel_key(Eigen::Vector3d(-2147483649.0, 0, 0), 1.0));
}

TEST_CASE("voxel hash separates the keys of a dense grid", "[voxel]") {
  // 40^3 neighbouring keys around the origin (negative ones included): all hashes distinct,
  // and the low 12 bits (a 4096-bucket table) are well spread.
  ulc::VoxelKeyHash hash;
  std::unordered_set<std::size_t> hashes;
  std::vector<int> bucket_load(4096, 0);
  for (int x = -20; x < 20; ++x)
    for (int y = -20; y < 20; ++y)
      for (int z = -20; z < 20; ++z) {
        const std::size_t h = hash(ulc::VoxelKey{x, y, z});
        hashes.insert(h);
        ++bucket_load[h & 4095];
      }
  CHECK(hashes.size() == 40u * 40u * 40u);
  const int max_load = *std::max_element(bucket_load.begin(), bucket_load.end());
  CHECK(max_load < 40);  // the mean is 15.6; a poor hash piles hundreds into a bucket
}

TEST_CASE("VoxelMap keeps insertion order, whatever the keys", "[voxel]") {
  ulc::VoxelMap<int> map;
  const std::vector<ulc::VoxelKey> keys = {{5, 0, 0}, {-3, 2, 1}, {0, 0, 0}, {100, -100, 7}};
  for (std::size_t i = 0; i < keys.size(); ++i) map[keys[i]] = static_cast<int>(i) * 10;
  map[keys[1]] += 1;  // existing key: same entry
  const auto [pos, inserted] = map.try_emplace(keys[2], 99);
  CHECK_FALSE(inserted);
  CHECK(pos == 2);
  REQUIRE(map.size() == 4);
  std::size_t i = 0;
  for (const auto& entry : map) {
    CHECK(entry.key == keys[i]);
    ++i;
  }
  CHECK(map.at_position(1).value == 11);
  CHECK(*map.find(keys[3]) == 30);
  CHECK(map.find(ulc::VoxelKey{1, 2, 3}) == nullptr);
  CHECK(map.position(keys[3]) == std::optional<std::size_t>(3));
  CHECK_FALSE(map.contains(ulc::VoxelKey{1, 2, 3}));
}

TEST_CASE("VoxelMap agrees with std::map through many insertions and rehashes", "[voxel]") {
  std::mt19937 rng(131);
  std::uniform_int_distribution<int> coord(-40, 40);  // small range: many repeated keys
  ulc::VoxelMap<int> map;
  std::map<ulc::VoxelKey, std::pair<std::size_t, int>> reference;  // key -> (position, count)
  std::vector<ulc::VoxelKey> order;
  for (int i = 0; i < 50000; ++i) {
    const ulc::VoxelKey key{coord(rng), coord(rng), coord(rng) / 8};
    ++map[key];
    auto it = reference.find(key);
    if (it == reference.end()) {
      reference.emplace(key, std::make_pair(order.size(), 1));
      order.push_back(key);
    } else {
      ++it->second.second;
    }
  }
  REQUIRE(map.size() == reference.size());
  for (const auto& [key, pos_count] : reference) {
    REQUIRE(map.position(key) == std::optional<std::size_t>(pos_count.first));
    CHECK(*map.find(key) == pos_count.second);
  }
  for (std::size_t i = 0; i < order.size(); ++i) CHECK(map.at_position(i).key == order[i]);
  CHECK_FALSE(map.contains(ulc::VoxelKey{1000, 0, 0}));
  map.clear();
  CHECK(map.empty());
  CHECK_FALSE(map.contains(order[0]));
  map[order[0]] = 5;
  CHECK(map.size() == 1);
}
