// A success whose own covariance does not vouch for it (pipeline/confidence.hpp): its 3-sigma
// bound beyond 10 cm or 1 deg along some direction is named, with the direction; and JEEP's answer
// whose two directions end farther apart than those bars.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "pipeline/confidence.hpp"

namespace {

ulc::PairCalibration success_with_covariance(const ulc::Mat6d& covariance) {
  ulc::PairCalibration r;
  r.success = true;
  r.status = ulc::CalibrateStatus::ok;
  r.covariance_6x6 = covariance;
  r.hots.emplace();  // HOTS's answer (run: refined)
  return r;
}

bool mentions(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

constexpr double kRadiansPerDegree = 3.14159265358979323846 / 180.0;

}  // namespace

TEST_CASE("a covariance within a success's bounds vouches for it", "[calibrate][confidence]") {
  // sigma 5 cm along x: 4.6 % beyond 10 cm; 0.5 deg: 4.6 % beyond 1 deg; both within 5 %.
  ulc::Mat6d c = ulc::Mat6d::Zero();
  c.diagonal() << 0.05 * 0.05, 0.01 * 0.01, 0.01 * 0.01,
      0.5 * kRadiansPerDegree * 0.5 * kRadiansPerDegree, 1e-8, 1e-8;
  CHECK(ulc::calibrate_detail::loosely_pinned(success_with_covariance(c), {}).empty());
}

TEST_CASE("a loose translation is named with its direction, sigma and chance",
          "[calibrate][confidence]") {
  ulc::Mat6d c = ulc::Mat6d::Identity() * 1e-8;
  c(0, 0) = 0.06 * 0.06;  // sigma 6 cm along x: P(|x| > 10 cm) = 9.6 %
  const std::string why = ulc::calibrate_detail::loosely_pinned(success_with_covariance(c), {});
  INFO(why);
  CHECK(mentions(why, "a 10 % chance that it is more than 10 cm off along x of the base frame"));
  CHECK(mentions(why, "(sigma 6.0 cm)"));
}

TEST_CASE("a loose rotation is named with its axis, sigma and chance", "[calibrate][confidence]") {
  ulc::Mat6d c = ulc::Mat6d::Identity() * 1e-8;
  const double s = 0.6 * kRadiansPerDegree / std::sqrt(2.0);  // 0.6 deg about the y = z diagonal
  c.block<2, 2>(4, 4) << s * s, s * s, s * s, s * s;
  const std::string why = ulc::calibrate_detail::loosely_pinned(success_with_covariance(c), {});
  INFO(why);
  CHECK(mentions(why, "more than 1.0 deg off about y and z"));
  CHECK(mentions(why, "(sigma 0.60 deg)"));
}

TEST_CASE("failures, results without a covariance and JEEP's answers are not judged",
          "[calibrate][confidence]") {
  ulc::Mat6d c = ulc::Mat6d::Identity();
  auto failed = success_with_covariance(c);
  failed.success = false;
  CHECK(ulc::calibrate_detail::loosely_pinned(failed, {}).empty());
  auto none = success_with_covariance(c);
  none.covariance_6x6.reset();
  CHECK(ulc::calibrate_detail::loosely_pinned(none, {}).empty());
  auto jeeps = success_with_covariance(c);  // JEEP's cell jackknife is not judged
  jeeps.hots.reset();
  CHECK(ulc::calibrate_detail::loosely_pinned(jeeps, {}).empty());
}

namespace {

/// JEEP's success (HOTS skipped) whose two directions ended `gap_m` and `gap_deg` apart.
ulc::PairCalibration jeeps_success(double gap_m, double gap_deg) {
  ulc::PairCalibration r;
  r.success = true;
  r.status = ulc::CalibrateStatus::ok;
  r.jeep.emplace();
  r.jeep->two_way = true;
  r.jeep->two_way_gap_translation = gap_m;
  r.jeep->two_way_gap_rotation = gap_deg * kRadiansPerDegree;
  return r;
}

}  // namespace

TEST_CASE("JEEP's answer whose two directions disagree beyond a success's bars is named",
          "[calibrate][confidence]") {
  using ulc::calibrate_detail::directions_disagree;
  CHECK(directions_disagree(jeeps_success(0.099, 0.99), {}).empty());
  const std::string far = directions_disagree(jeeps_success(0.196, 0.32), {});
  INFO(far);
  CHECK(mentions(far, "end 19.6 cm and 0.32 deg apart, more than the 10 cm or 1 deg"));
  CHECK_FALSE(directions_disagree(jeeps_success(0.02, 1.5), {}).empty());  // the rotation alone
}

TEST_CASE("the two-way gap is judged only on JEEP's own successes, and can be turned off",
          "[calibrate][confidence]") {
  using ulc::calibrate_detail::directions_disagree;
  auto hots = jeeps_success(0.3, 2.0);  // HOTS refined the answer: its covariance judges it
  hots.hots.emplace();
  CHECK(directions_disagree(hots, {}).empty());
  auto failed = jeeps_success(0.3, 2.0);
  failed.success = false;
  CHECK(directions_disagree(failed, {}).empty());
  auto one_way = jeeps_success(0.3, 2.0);  // the backward registration did not end usable
  one_way.jeep->two_way = false;
  CHECK(directions_disagree(one_way, {}).empty());
  ulc::VouchOptions off;
  off.judge_two_way_gap = false;
  CHECK(directions_disagree(jeeps_success(0.3, 2.0), off).empty());
  auto skipped = jeeps_success(0.3, 2.0);  // HOTS skipped itself: JEEP's answer stands
  skipped.hots.emplace();
  skipped.hots->run = ulc::HotsRun::skipped;
  CHECK_FALSE(directions_disagree(skipped, {}).empty());
}
