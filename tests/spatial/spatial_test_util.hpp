// Shared helpers for the spatial tests: seeded random clouds and brute-force neighbour search.
#pragma once

#include <algorithm>
#include <cstddef>
#include <random>
#include <utility>
#include <vector>

#include "ulc/core/kdtree.hpp"
#include "ulc/core/types.hpp"

namespace spatial_test {

template <typename S>
std::vector<ulc::Vec3<S>> random_cloud(std::size_t n, S half_extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-static_cast<double>(half_extent),
                                           static_cast<double>(half_extent));
  std::vector<ulc::Vec3<S>> cloud(n);
  for (auto& p : cloud) p = ulc::Vec3<double>(u(rng), u(rng), u(rng)).cast<S>();
  return cloud;
}

/// (squared distance, index) of every finite point, sorted the way KdTree promises.
template <typename S>
std::vector<std::pair<S, std::size_t>> brute_force_sorted(const std::vector<ulc::Vec3<S>>& cloud,
                                                          const ulc::Vec3<S>& q) {
  std::vector<std::pair<S, std::size_t>> all;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (ulc::is_finite_point(cloud[i])) all.emplace_back(ulc::squared_distance(cloud[i], q), i);
  std::sort(all.begin(), all.end());
  return all;
}

}  // namespace spatial_test
