// What the data cannot vouch for (pipeline/vouch.hpp): a clock offset nobody estimated, and a
// LiDAR whose frames carry no per-point times, on short simulated 64-32 and 64-horizon drives.
#include <catch2/catch.hpp>

#include <optional>
#include <string>

#include "calibrate_test_util.hpp"
#include "pipeline/calibrate.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/sim/scenario.hpp"
#include "ulc/sim/simulate.hpp"

namespace {

using ulc::Stage;

/// A decimated drive of `scenario`; a target clock offset and a parked vehicle when asked.
ulc::sim::Dataset drive(const char* scenario, double seconds, std::optional<double> offset,
                        bool parked = false) {
  ulc::sim::SimulationOptions o;
  o.seconds = seconds;
  o.seed = 2;
  o.decimation = 4;
  o.target_clock_offset_s = offset;
  if (parked) o.static_at_s = 3.0;
  return ulc::sim::simulate(*ulc::sim::scenario(scenario), o).dataset;
}

/// One second of `scenario` with the target's per-point times removed.
ulc::sim::Dataset untimed_target(const char* scenario) {
  auto d = drive(scenario, 1.0, std::nullopt);
  for (auto& f : d.lidars.at(1).frames) f.times.clear();
  return d;
}

ulc::PairCalibration terra_jeep(const ulc::sim::Dataset& d, std::optional<double> known_offset) {
  ulc::CalibrateOptions o;
  o.stages = {Stage::terra, Stage::jeep};
  o.time_offset_s = known_offset;
  const auto& a = d.lidars.at(0);
  const auto& b = d.lidars.at(1);
  return ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("a 50 ms clock offset with terra,jeep on a moving rig is not a success",
          "[calibrate][vouch]") {
  const auto d = drive("64-32", 3.0, 0.05);
  const auto r = terra_jeep(d, std::nullopt);
  INFO(ulc::to_string(r.status) << ": " << r.reason);
  const auto e = ulc::pose_error(d.pairs.at(0).T_base_target, r.T_base_target);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m");
  CHECK_FALSE(r.success);
  CHECK(r.status == ulc::CalibrateStatus::time_offset_unestimated);
  REQUIRE(r.clock);
  CHECK(r.clock->source == ulc::ClockSource::not_estimated);
  CHECK(contains(r.reason, "the clock offset was not estimated"));
  CHECK(contains(r.clock->note, "an offset of 1 ms moves the translation by"));
  CHECK(r.clock->speed_mps > 1.0);  // the town drive
}

TEST_CASE("a known offset calibrates the same drive, and the result says it was given",
          "[calibrate][vouch]") {
  const auto d = drive("64-32", 1.0, 0.05);
  const auto r = terra_jeep(d, 0.05);
  INFO(ulc::to_string(r.status) << ": " << r.reason);
  REQUIRE(r.success);
  REQUIRE(r.clock);
  CHECK(r.clock->source == ulc::ClockSource::given);
  CHECK(ulc::is_calibration_success(ulc::pose_error(d.pairs.at(0).T_base_target, r.T_base_target)));
}

TEST_CASE("a parked rig with an unestimated offset stays ok: no offset can move it",
          "[calibrate][vouch]") {
  // Five frames: too few for the stillness check, JEEP's speed says no offset matters. Ten:
  // the check finds the rig standing.
  const auto [seconds, verdict] =
      GENERATE(table<double, std::string>({{0.5, "slow"}, {1.0, "parked"}}));
  const auto d = drive("64-32", seconds, 0.05, true);
  const auto r = terra_jeep(d, std::nullopt);
  INFO(seconds << " s: " << ulc::to_string(r.status) << ": " << r.reason);
  REQUIRE(r.success);
  REQUIRE(r.clock);
  CHECK(r.clock->source == ulc::ClockSource::not_estimated);
  CHECK(r.clock->verdict == verdict);
  CHECK(contains(r.clock->note, "was not estimated"));
  CHECK(ulc::is_calibration_success(ulc::pose_error(d.pairs.at(0).T_base_target, r.T_base_target)));
}

TEST_CASE("a spinning target without point times is timed from azimuth and named",
          "[calibrate][vouch]") {
  const auto d = untimed_target("64-32");
  const auto r = terra_jeep(d, 0.0);
  INFO(ulc::to_string(r.status) << ": " << r.reason);
  CHECK(r.point_times_base.source == ulc::PointTimeSource::per_point);
  CHECK(r.point_times_target.source == ulc::PointTimeSource::synthesised_from_azimuth);
  CHECK(r.point_times_target.frames_without == d.lidars.at(1).frames.size());
  REQUIRE(r.success);
  const auto e = ulc::pose_error(d.pairs.at(0).T_base_target, r.T_base_target);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m");
  CHECK(ulc::is_calibration_success(e));
}

TEST_CASE("a moving Livox target without point times is not a success, and is named",
          "[calibrate][vouch]") {
  const auto d = untimed_target("64-horizon");
  const auto r = terra_jeep(d, 0.0);
  INFO(ulc::to_string(r.status) << ": " << r.reason);
  CHECK(r.point_times_target.source == ulc::PointTimeSource::none);
  CHECK_FALSE(r.point_times_target.note.empty());
  CHECK_FALSE(r.success);
  CHECK(r.status == ulc::CalibrateStatus::point_times_missing);
  CHECK(contains(r.reason, "no per-point time"));
}
