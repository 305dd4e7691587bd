// The frame nearest an instant (ulc/core/nearest_time.hpp).
#include <catch2/catch.hpp>
#include <vector>

#include "ulc/core/nearest_time.hpp"

TEST_CASE("the nearest time is found within the range asked, the earliest on ties",
          "[core][nearest_time]") {
  const std::vector<double> t{0.0, 0.1, 0.2, 0.3, 0.4};
  CHECK(ulc::nearest_time(t, 0.26) == 3);
  CHECK(ulc::nearest_time(t, -5.0) == 0);
  CHECK(ulc::nearest_time(t, 9.0) == 4);
  CHECK(ulc::nearest_time({0.0, 1.0}, 0.5) == 0);  // a tie: the earlier
  // Within [first, first + count): counted from first.
  CHECK(ulc::nearest_time(t, 0.0, 2, 2) == 0);    // 0.2 is the range's nearest to 0
  CHECK(ulc::nearest_time(t, 0.39, 1, 2) == 1);   // 0.2, not 0.4 outside the range
  CHECK(ulc::nearest_time(t, 0.39, 3, 99) == 1);  // a count past the end stops at the end
  CHECK(ulc::nearest_time(t, 0.1, 7, 2) == 0);    // an empty range
  CHECK(ulc::nearest_time({}, 0.1) == 0);
  CHECK(ulc::nearest_time({0.3, 0.0, 0.2}, 0.05) == 1);  // unsorted times
}
