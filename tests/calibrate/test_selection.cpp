// Choosing the stretch of a long drive (pipeline/selection.hpp): a drive that fits the budget is
// used whole; on a drive that moves and then parks, the chosen stretch is the moving one, whose
// rotation and speed change the survey measures; the choice does not depend on threads.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>

#include <vector>

#include "calibrate_test_util.hpp"
#include "pipeline/selection.hpp"

using namespace calibrate_test;

namespace {

/// 4 s of the town drive, then the last frame again for 6 s: the vehicle parked.
struct DriveThenPark {
  std::vector<ulc::PointCloud<float>> frames;
  std::vector<double> times;
  DriveThenPark() {
    const auto d = simulate_64_32(4.0, 2, 4);
    const auto& base = d.lidars.at(0);
    frames = base.frames;
    times = base.timestamps;
    const double period = times[1] - times[0];
    while (times.back() < base.timestamps.back() + 6.0) {
      frames.push_back(base.frames.back());
      times.push_back(times.back() + period);
    }
  }
};

ulc::Selection survey(const DriveThenPark& d, const ulc::SelectionOptions& o) {
  ulc::DriveSurvey<float> s(o, d.times[1] - d.times[0]);
  for (std::size_t k = 0; k < d.frames.size(); ++k) s.add(d.frames[k], d.times[k]);
  return s.select(d.times.front(), d.times.back());
}

}  // namespace

TEST_CASE("a drive within the budget is used whole", "[calibrate][selection]") {
  static const DriveThenPark d;
  ulc::SelectionOptions o;
  o.budget_s = 20.0;
  const ulc::Selection s = survey(d, o);
  CHECK_FALSE(s.applied);
  CHECK(s.windows.empty());
  CHECK_THAT(s.why, Catch::Contains("fits the budget"));
}

TEST_CASE("the stretch chosen on a drive that then parks is the moving one",
          "[calibrate][selection]") {
  static const DriveThenPark d;
  ulc::SelectionOptions o;
  o.budget_s = 3.0;
  o.step_s = 1.0;
  const ulc::Selection s = survey(d, o);
  INFO(s.why);
  REQUIRE(s.applied);
  REQUIRE(s.windows.size() >= 7);  // starts 0, 1, ..., 7 s of a 10 s drive
  CHECK(s.end_s - s.start_s == Approx(3.0));
  CHECK(s.start_s < 4.0);  // it holds driving (the stop itself is a speed change)
  const ulc::StretchScore& moving = s.windows[s.chosen];
  const ulc::StretchScore& parked = s.windows.back();
  CHECK(parked.start_s >= 4.0);
  CHECK(parked.rotation_rad.norm() < 1e-3);
  CHECK(parked.speed_change_mps < 0.1);
  CHECK(moving.rotation_rad.norm() > 10.0 * parked.rotation_rad.norm());
  CHECK(moving.score > parked.score);
  tbb::task_arena one(1);
  const ulc::Selection again = one.execute([&] { return survey(d, o); });
  CHECK(again.chosen == s.chosen);
  CHECK(again.windows.back().score == s.windows.back().score);
}
