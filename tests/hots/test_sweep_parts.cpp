// A frame's sweep parts (hots/refine_prepare.hpp, order_by_part): views into the frame's own
// points, ordered part after part, so that the parts are not a second copy of the frame.
#include <catch2/catch.hpp>
#include <cstddef>
#include <random>
#include <vector>

#include "hots/refine_prepare.hpp"

namespace sweep_parts_test {

using Points = std::vector<ulc::Vec3<float>>;

/// Point i is (i, 0, 0): where it went is readable from its x.
Points numbered(std::size_t n) {
  Points out;
  for (std::size_t i = 0; i < n; ++i) out.emplace_back(static_cast<float>(i), 0.0f, 0.0f);
  return out;
}

TEST_CASE("sweep parts are views into the frame's points, ordered part after part",
          "[hots][sweep_parts]") {
  constexpr std::size_t kPoints = 1000;
  constexpr int kParts = 4;
  constexpr double kPeriod = 0.1;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> when(0.0, kPeriod);
  std::vector<double> times(kPoints);
  for (double& t : times) t = when(rng);
  Points points = numbered(kPoints);
  const std::pair<Isometry3d, double> motion{Isometry3d::Identity(), kPeriod};
  const auto sp = hots::hots_detail::order_by_part(points, &times, motion, kParts);

  REQUIRE(sp.parts.size() == static_cast<std::size_t>(kParts));
  REQUIRE(sp.fraction.size() == sp.parts.size());
  const ulc::Vec3<float>* next = points.data();
  for (int j = 0; j < kParts; ++j) {
    const ulc::PointSpan<float>& part = sp.parts[static_cast<std::size_t>(j)];
    CHECK(part.begin() == next);  // contiguous, in part order, inside the frame's own buffer
    next = part.end();
    double fraction_sum = 0.0;
    double previous = -1.0;
    for (const auto& p : part) {
      const std::size_t original = static_cast<std::size_t>(p.x());
      const double f = times[original] / kPeriod;
      CHECK(f >= j / double(kParts));  // its time falls in its part
      CHECK(f < (j + 1) / double(kParts));
      CHECK(p.x() > previous);  // stable: the frame's order within a part
      previous = p.x();
      fraction_sum += f;
    }
    REQUIRE_FALSE(part.empty());
    CHECK(sp.fraction[static_cast<std::size_t>(j)] ==
          Approx(fraction_sum / static_cast<double>(part.size())));
  }
  CHECK(next == points.data() + points.size());  // every point in exactly one part
}

TEST_CASE("a frame without point times is one part at fraction 0, in its own order",
          "[hots][sweep_parts]") {
  Points points = numbered(50);
  const Points before = points;
  const auto sp = hots::hots_detail::order_by_part(
      points, nullptr, std::pair<Isometry3d, double>{Isometry3d::Identity(), 0.1}, 4);
  REQUIRE(sp.parts.size() == 1);
  CHECK(sp.parts[0].begin() == points.data());
  CHECK(sp.parts[0].size() == points.size());
  CHECK(sp.fraction[0] == 0.0);
  CHECK(points == before);
}

}  // namespace sweep_parts_test
