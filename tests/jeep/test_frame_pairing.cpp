// Frame pairing by timestamp: nearest within the gap, each target frame used once, clock
// offsets applied, unusable timestamps refused.
#include <catch2/catch.hpp>
#include <vector>

#include "odometry/frame_pairing.hpp"

using odometry::FramePair;

namespace {

std::vector<std::pair<std::size_t, std::size_t>> as_pairs(const std::vector<FramePair>& p) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  for (const auto& x : p) out.emplace_back(x.a, x.b);
  return out;
}

}  // namespace

TEST_CASE("pairing: nearest frame within half a period, unpaired frames skipped",
          "[jeep][pairing]") {
  const std::vector<double> a = {0.00, 0.10, 0.20, 0.30, 0.40, 0.50};
  // b runs 30 ms late, misses the frame near 0.2 and has an extra one at the end.
  const std::vector<double> b = {0.03, 0.13, 0.33, 0.43, 0.53, 0.63};
  CHECK(odometry::frame_period(a) == Approx(0.1));
  const auto pairs = odometry::pair_frames(a, b, 0.0, 0.05);
  const std::vector<std::pair<std::size_t, std::size_t>> expected = {
      {0, 0}, {1, 1}, {3, 2}, {4, 3}, {5, 4}};
  CHECK(as_pairs(pairs) == expected);
}

TEST_CASE("pairing: a target frame pairs once, with the nearer base frame", "[jeep][pairing]") {
  // b at half the rate: both a frames around each b frame want it.
  const std::vector<double> a = {0.00, 0.05, 0.10, 0.15, 0.20};
  const std::vector<double> b = {0.01, 0.11, 0.21};
  const auto pairs = odometry::pair_frames(a, b, 0.0, 0.05);
  const std::vector<std::pair<std::size_t, std::size_t>> expected = {{0, 0}, {2, 1}, {4, 2}};
  CHECK(as_pairs(pairs) == expected);
}

TEST_CASE("pairing: the clock offset moves b into a's clock", "[jeep][pairing]") {
  // t_base = t_target + offset: b's clock reads 1000 s less.
  const std::vector<double> a = {1000.00, 1000.10, 1000.20};
  const std::vector<double> b = {0.02, 0.12, 0.22};
  CHECK(odometry::pair_frames(a, b, 0.0, 0.05).empty());
  CHECK(odometry::pair_frames(a, b, 1000.0, 0.05).size() == 3);
}

TEST_CASE("pairing: unusable timestamps give no pairs", "[jeep][pairing]") {
  const std::vector<double> a = {0.0, 0.1, 0.2};
  CHECK(odometry::pair_frames(a, {0.0, std::nan(""), 0.2}, 0.0, 0.05).empty());
  CHECK(odometry::pair_frames(a, {0.2, 0.1, 0.0}, 0.0, 0.05).empty());
  CHECK(odometry::pair_frames(a, {}, 0.0, 0.05).empty());
  CHECK_FALSE(odometry::timestamps_usable({0.0, 1.0, 0.5}));
  CHECK(odometry::frame_period({1.0}) == 0.0);
}
