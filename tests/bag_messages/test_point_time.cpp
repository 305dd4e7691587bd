// Per-point time conventions decided from the values, never from the name alone.
#include <catch2/catch.hpp>
#include <vector>

#include "ulc/bags/point_time.hpp"

namespace {

using ulc::bags::PointTimeInfo;
using ulc::bags::TimeReference;
using ulc::io::ScalarType;

PointTimeInfo info_of(const char* field, ScalarType type) {
  PointTimeInfo info;
  info.field = field;
  info.type = type;
  return info;
}

constexpr double kStampS = 1700000000.25;

}  // namespace

TEST_CASE("point times: relative seconds, relative nanoseconds", "[bags]") {
  std::vector<double> t = {0.0, 0.05, 0.099};
  auto info = info_of("time", ScalarType::float32);
  REQUIRE(ulc::bags::resolve_point_times(t, kStampS, info));
  REQUIRE(info.reference == TimeReference::relative);
  REQUIRE(info.seconds_per_unit == 1.0);
  REQUIRE(t[2] == 0.099);

  std::vector<double> ns = {0.0, 5e7, 9.9e7};
  info = info_of("t", ScalarType::uint32);
  REQUIRE(ulc::bags::resolve_point_times(ns, kStampS, info));
  REQUIRE(info.reference == TimeReference::relative);
  REQUIRE(info.seconds_per_unit == 1e-9);
  REQUIRE(ns[1] == Approx(0.05).margin(1e-12));
  // Velodyne's times may end at the stamp (negative offsets).
  std::vector<double> before = {-0.1, -0.05, 0.0};
  info = info_of("time", ScalarType::float32);
  REQUIRE(ulc::bags::resolve_point_times(before, kStampS, info));
  REQUIRE(before[0] == -0.1);
}

TEST_CASE("point times: absolute seconds and nanoseconds become relative to the stamp", "[bags]") {
  std::vector<double> s = {kStampS + 0.001, kStampS + 0.09};
  auto info = info_of("timestamp", ScalarType::float64);
  REQUIRE(ulc::bags::resolve_point_times(s, kStampS, info));
  REQUIRE(info.reference == TimeReference::absolute);
  REQUIRE(info.seconds_per_unit == 1.0);
  REQUIRE(s[0] == Approx(0.001).margin(1e-6));
  REQUIRE(s[1] == Approx(0.09).margin(1e-6));

  std::vector<double> ns = {kStampS * 1e9 + 2e6, kStampS * 1e9 + 8e7};  // livox_ros_driver2
  info = info_of("timestamp", ScalarType::float64);
  REQUIRE(ulc::bags::resolve_point_times(ns, kStampS, info));
  REQUIRE(info.reference == TimeReference::absolute);
  REQUIRE(info.seconds_per_unit == 1e-9);
  REQUIRE(ns[0] == Approx(0.002).margin(1e-6));

  std::vector<double> us = {kStampS * 1e6 + 3e3};
  info = info_of("timestamp", ScalarType::uint64);
  REQUIRE(ulc::bags::resolve_point_times(us, kStampS, info));
  REQUIRE(info.seconds_per_unit == 1e-6);
  REQUIRE(us[0] == Approx(0.003).margin(1e-6));
  REQUIRE(ulc::bags::describe(info).find("absolute") != std::string::npos);
}

TEST_CASE("point times: all zero means none; values of no known unit are refused", "[bags]") {
  std::vector<double> zero = {0.0, 0.0, 0.0};
  auto info = info_of("t", ScalarType::uint32);
  REQUIRE(ulc::bags::resolve_point_times(zero, kStampS, info));
  REQUIRE(zero.empty());
  REQUIRE(info.reference == TimeReference::none);
  REQUIRE(ulc::bags::describe(info) == "`t` uint32 all zero: ignored");

  std::vector<double> odd = {5e5, 6e5};  // 5.8 days of seconds, not the stamp either
  info = info_of("time", ScalarType::float64);
  REQUIRE_FALSE(ulc::bags::resolve_point_times(odd, kStampS, info));
  std::vector<double> wide = {0.0, 30.0};  // a "sweep" of 30 s
  info = info_of("time", ScalarType::float32);
  REQUIRE_FALSE(ulc::bags::resolve_point_times(wide, kStampS, info));
}

TEST_CASE("point times: a simulated clock near 0 reads relative", "[bags]") {
  std::vector<double> t = {0.0, 0.05};
  auto info = info_of("time", ScalarType::float32);
  REQUIRE(ulc::bags::resolve_point_times(t, 0.1, info));
  REQUIRE(info.reference == TimeReference::relative);
  REQUIRE(t[1] == 0.05);
}
