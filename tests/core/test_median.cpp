// Medians (ulc/core/median.hpp): odd and even counts, the upper median's choice of a sample,
// frame periods from times with a dropped frame, and the empty cases.
#include <catch2/catch.hpp>

#include <vector>

#include "ulc/core/median.hpp"

TEST_CASE("the median of an odd and an even count", "[core][median]") {
  CHECK(ulc::median({}) == 0.0);
  CHECK(ulc::median({0.4, 0.1, 0.3}) == 0.3);
  CHECK(ulc::median({0.4, 0.1, 0.3, 0.2}) == Approx(0.25));
  CHECK(ulc::median({2.0, -1.0}) == Approx(0.5));
}

TEST_CASE("the upper median is a sample: the upper of the middle two", "[core][median]") {
  CHECK(ulc::upper_median({}) == 0.0);
  CHECK(ulc::upper_median({5.0}) == 5.0);
  CHECK(ulc::upper_median({0.4, 0.1, 0.3, 0.2}) == 0.3);
  CHECK(ulc::upper_median({3.0, 1.0, 2.0}) == 2.0);
}

TEST_CASE("the median step of frame times ignores a dropped frame", "[core][median]") {
  // 10 Hz with one frame missing (a 0.2 s gap) and the times out of step by a jitter.
  const std::vector<double> times{0.0, 0.1, 0.2, 0.4, 0.5, 0.6001, 0.7};
  CHECK(ulc::median_step(times) == Approx(0.1).margin(1e-3));
  CHECK(ulc::median_step({}) == 0.0);
  CHECK(ulc::median_step({1.0}) == 0.0);
  CHECK(ulc::median_step({1.0, 1.25}) == Approx(0.25));
}
