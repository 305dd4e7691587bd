// A success whose own covariance does not vouch for it (pipeline/confidence.hpp): its 3-sigma
// bound beyond 10 cm or 1 deg along some direction is named, with the direction.
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
