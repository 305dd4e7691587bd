// The automatic choice of HOTS's odometry (pipeline/odometry_choice.hpp): a base that sees all
// around on a long enough drive gets its own odometry; a narrow base or a short drive the joint
// one; an explicit choice is kept. And in the pipeline: the choice is reported, and the base's
// odometry chosen automatically gives the answer asked-for base odometry gives, to the bit; and
// when it ends without a success, the joint odometry's answer is the call's.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <vector>

#include "calibrate_test_util.hpp"
#include "odometry/run_odometry.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/odometry_choice.hpp"

using namespace calibrate_test;
using ulc::HotsOdometry;

namespace {

/// Points at `range` m, every 1 deg of azimuth within [from, to] deg, on three rings in height.
ulc::PointCloud<float> arc(double from_deg, double to_deg, double range) {
  ulc::PointCloud<float> cloud;
  for (double a = from_deg; a <= to_deg; a += 1.0)
    for (const float z : {-1.0f, 0.0f, 1.0f}) {
      const double r = a * 3.141592653589793 / 180.0;
      cloud.points.emplace_back(static_cast<float>(range * std::cos(r)),
                                static_cast<float>(range * std::sin(r)), z);
    }
  return cloud;
}

}  // namespace

TEST_CASE("azimuth coverage: all around, a narrow view, and what does not count",
          "[calibrate][odometry_choice]") {
  const ulc::OdometryChoiceOptions o;
  CHECK(ulc::azimuth_coverage(arc(-180.0, 179.0, 20.0), o) == 1.0);
  // 70 deg ahead (an Avia's view): 14 or 15 of the 72 sectors of 5 deg.
  const double avia = ulc::azimuth_coverage(arc(-35.0, 35.0, 20.0), o);
  CHECK(avia >= 14.0 / 72.0);
  CHECK(avia <= 15.0 / 72.0);
  // The vehicle's own body within min_range_m all around, and non-finite points: not counted.
  ulc::PointCloud<float> body = arc(-35.0, 35.0, 20.0);
  for (const auto& p : arc(-180.0, 179.0, 1.5).points) body.points.push_back(p);
  body.points.emplace_back(std::nanf(""), 1.0f, 0.0f);
  body.points.emplace_back(INFINITY, -INFINITY, 0.0f);
  CHECK(ulc::azimuth_coverage(body, o) == avia);
  CHECK(ulc::azimuth_coverage(ulc::PointCloud<float>{}, o) == 0.0);
}

TEST_CASE("the choice: base for a long drive of an all-around base, else joint, or as asked",
          "[calibrate][odometry_choice]") {
  const ulc::OdometryChoiceOptions o;  // 30 s, 90 % of the azimuth
  const std::vector<ulc::PointCloud<float>> spinning(3, arc(-180.0, 179.0, 20.0));
  const std::vector<ulc::PointCloud<float>> narrow(3, arc(-39.5, 39.5, 20.0));  // 16 sectors
  const std::vector<double> long_drive{100.0, 130.0, 160.0};   // three frames of 30 s: 90 s
  const std::vector<double> short_drive{100.0, 105.0, 110.0};  // 15 s

  const auto chosen = ulc::choose_odometry(HotsOdometry::automatic, spinning, long_drive, o);
  CHECK(chosen.odometry == HotsOdometry::base);
  CHECK_THAT(chosen.why, Catch::Contains("lasts 90.0 s") && Catch::Contains("100 %"));

  const auto brief = ulc::choose_odometry(HotsOdometry::automatic, spinning, short_drive, o);
  CHECK(brief.odometry == HotsOdometry::joint);
  CHECK_THAT(brief.why, Catch::Contains("lasts 15.0 s") && Catch::Contains("30 s"));

  const auto ahead = ulc::choose_odometry(HotsOdometry::automatic, narrow, long_drive, o);
  CHECK(ahead.odometry == HotsOdometry::joint);
  CHECK_THAT(ahead.why, Catch::Contains("sees 22 %"));

  // The median of the first, middle and last frame: one frame that sees little does not decide.
  auto one_blocked = spinning;
  one_blocked[1] = arc(-10.0, 10.0, 20.0);
  CHECK(ulc::choose_odometry(HotsOdometry::automatic, one_blocked, long_drive, o).odometry ==
        HotsOdometry::base);

  for (const HotsOdometry asked : {HotsOdometry::base, HotsOdometry::joint}) {
    CHECK(ulc::choose_odometry(asked, narrow, short_drive, o).odometry == asked);
    CHECK(ulc::choose_odometry(asked, spinning, long_drive, o).odometry == asked);
  }
  CHECK(
      ulc::choose_odometry(HotsOdometry::automatic, spinning, std::vector<double>{}, o).odometry ==
      HotsOdometry::joint);
}

TEST_CASE("the pipeline reports its choice, and the base's odometry chosen is the one asked for",
          "[calibrate][hots][odometry_choice]") {
  const auto& d = drive_64_32_hots();  // 3 s: the joint odometry by default
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  ulc::CalibrateOptions o;
  o.time_offset_s = 0.0;
  REQUIRE(o.tuning.hots_odometry == HotsOdometry::automatic);  // the default
  const auto by_default = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
  REQUIRE(by_default.hots);
  CHECK(by_default.hots->odometry == HotsOdometry::joint);
  CHECK_THAT(by_default.hots->odometry_choice, Catch::Contains("joint: the drive lasts"));
  CHECK_FALSE(by_default.base_work.odometry);

  // A span the 3 s drive passes: the HDL-64E sees all around, so the base's own odometry, and
  // then the same answer as when it is asked for.
  o.tuning.odometry_choice.min_duration_s = 1.0;
  const auto chosen = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
  INFO(ulc::to_string(chosen.status) << ": " << chosen.reason);
  REQUIRE(chosen.hots);
  CHECK(chosen.hots->odometry == HotsOdometry::base);
  CHECK_THAT(chosen.hots->odometry_choice, Catch::StartsWith("base: the drive lasts"));
  CHECK(chosen.base_work.odometry);
  o.tuning.hots_odometry = HotsOdometry::base;
  const auto asked = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
  REQUIRE(asked.hots);
  CHECK(asked.hots->odometry == HotsOdometry::base);
  CHECK(same_bits(asked.T_base_target, chosen.T_base_target));
  CHECK(asked.status == chosen.status);

  // The base's odometry failing (here a shared one that registered nothing): the stages run
  // again on the joint odometry, and its answer is the call's, bit for bit.
  o.tuning.hots_odometry = HotsOdometry::automatic;
  auto failed = std::make_shared<odometry::OdometryResult>(*chosen.base_work.odometry);
  failed->status = odometry::OdometryStatus::no_pairs;
  o.base_work.odometry = failed;
  const auto fell_back = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
  INFO(ulc::to_string(fell_back.status) << ": " << fell_back.reason);
  REQUIRE(fell_back.hots);
  CHECK(fell_back.success);
  CHECK(fell_back.hots->odometry == HotsOdometry::joint);
  CHECK_THAT(fell_back.hots->odometry_choice,
             Catch::StartsWith("joint: the base's own odometry was tried first (base: ") &&
                 Catch::Contains("ended hots_failed"));
  o.tuning.hots_odometry = HotsOdometry::joint;
  o.base_work = {};
  const auto joint = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
  REQUIRE(joint.hots);
  CHECK_THAT(joint.hots->odometry_choice, Catch::Equals("asked for the joint odometry"));
  CHECK(same_bits(joint.T_base_target, fell_back.T_base_target));
  CHECK(joint.status == fell_back.status);
}
