// Frame times (ulc/io/frame_times.hpp, sequence.hpp): units recognised by magnitude or by the
// frame period, pcl_ros "sec.nsec" names told from decimal seconds, time order over name order,
// and refusals for what cannot be told apart.
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "ulc/io/frame_times.hpp"
#include "ulc/io/sequence.hpp"

using ulc::io::frame_time_unit;
using ulc::io::times_from_file_names;

namespace {

std::vector<std::filesystem::path> names(const std::vector<std::string>& stems) {
  std::vector<std::filesystem::path> out;
  for (const auto& s : stems) out.emplace_back("/data/top/" + s + ".pcd");
  return out;
}

/// pcl_ros names of `n` frames at 10 Hz from 1645000000.9523 s: "1645000001.52300000", ...
std::vector<std::string> pcl_ros_stems(int n) {
  std::vector<std::string> out;
  for (int k = 0; k < n; ++k) {
    const long long ns = 1645000000952300000LL + 100000000LL * k;
    out.push_back(std::to_string(ns / 1000000000LL) + "." + std::to_string(ns % 1000000000LL));
  }
  return out;
}

std::string unit_of(const std::vector<double>& times) {
  return frame_time_unit(times, "timestamps.txt", "frame times").name;
}

}  // namespace

TEST_CASE("frame times: the unit from Unix magnitude or from the median frame period",
          "[io][frame_times]") {
  CHECK(unit_of({0.0, 0.1, 0.2}) == std::string("seconds"));
  CHECK(unit_of({1645000000.0, 1645000000.1}) == std::string("seconds"));
  CHECK(unit_of({1645000000000.0, 1645000000100.0}) == std::string("milliseconds"));
  CHECK(unit_of({1645000000000000.0, 1645000000100000.0}) == std::string("microseconds"));
  CHECK(unit_of({1.645e18, 1.645e18 + 1e8}) == std::string("nanoseconds"));
  CHECK(unit_of({0.0, 100.0, 200.0}) == std::string("milliseconds"));      // 10 Hz from 0
  CHECK(unit_of({1e9, 1.1e9, 1.2e9}) == std::string("nanoseconds"));       // from 0, 1 s in
  CHECK(unit_of({1645000000.0, 1645000005.0}) == std::string("seconds"));  // slow capture
  CHECK(unit_of({7.0}) == std::string("seconds"));
  io_test::require_io_error(
      [] {
        unit_of({0.0, 1e-4, 2e-4});
      },
      {"timestamps.txt", "median step between frames is 0.0001"});
}

TEST_CASE("frame times: pcl_ros sec.nsec names against decimal seconds", "[io][frame_times]") {
  // ROS 2 pcl_ros: unpadded nanoseconds, 10 Hz from 0.0523 s into a second, so every tenth
  // count has 8 digits; the decimal reading puts those frames between others (irregular).
  const auto ros2 = times_from_file_names(names(pcl_ros_stems(12)));
  REQUIRE(ros2);
  CHECK((*ros2)[1] == Approx(1645000001.0523).epsilon(1e-15));
  // 1645000000.5000000 is: 5 000 000 ns, not half a second.
  const auto small = times_from_file_names(
      names({"1645000000.5000000", "1645000000.105000000", "1645000000.205000000"}));
  REQUIRE(small);
  CHECK((*small)[0] == Approx(1645000000.005).epsilon(1e-15));
  // Fixed precision decimal seconds; leading zeros; 9 digits: decimal.
  const auto fixed = times_from_file_names(names({"1645000000.100", "1645000000.200"}));
  REQUIRE(fixed);
  CHECK((*fixed)[1] == Approx(1645000000.2).epsilon(1e-15));
  const auto padded = times_from_file_names(names({"1645000000.05", "1645000000.15"}));
  REQUIRE(padded);
  CHECK((*padded)[0] == Approx(1645000000.05).epsilon(1e-15));
  // Integer names: 19 digits ns, 16 us, 13 ms, 10 s; a zero-padded index is no time.
  CHECK((*times_from_file_names(names({"1645000000123456789"})))[0] ==
        Approx(1645000000.123456789).epsilon(1e-15));
  CHECK((*times_from_file_names(names({"1645000000123456"})))[0] ==
        Approx(1645000000.123456).epsilon(1e-15));
  CHECK((*times_from_file_names(names({"1645000000123"})))[0] ==
        Approx(1645000000.123).epsilon(1e-15));
  CHECK_FALSE(times_from_file_names(names({"000042", "000043"})));
  CHECK_FALSE(times_from_file_names(names({"1645000000.1", "scan"})));
  // Varying fraction lengths regular both ways (or neither): refused.
  io_test::require_io_error(
      [] {
        times_from_file_names(names({"1645000000.100000000", "1645000000.20000000"}));
      },
      {"/data/top", "cannot tell which", "timestamps.txt"});
}

TEST_CASE("sequence: names that are times order the frames; equal times are refused",
          "[io][frame_times]") {
  io_test::TempDir dir;
  const std::vector<std::string> stems = pcl_ros_stems(12);
  for (std::size_t i = 0; i < stems.size(); ++i) {
    ulc::PointCloud<double> c;
    c.points.emplace_back(static_cast<double>(i), 0.0, 0.0);
    ulc::io::write_cloud(dir / (stems[i] + ".pcd"), c);
  }
  const ulc::io::Sequence seq(dir.path());
  CHECK(seq.time_source() == ulc::io::FrameTimeSource::file_name);
  CHECK(seq.frame(1).path.filename() == "1645000001.52300000.pcd");  // last by name
  CHECK(seq.frame(2).path.filename() == "1645000001.152300000.pcd");
  CHECK(seq.frame(1).timestamp == Approx(1645000001.0523).epsilon(1e-15));

  io_test::TempDir same;
  ulc::PointCloud<double> c;
  c.points.emplace_back(1.0, 0.0, 0.0);
  ulc::io::write_cloud(same / "1645000000100.pcd", c);     // ms
  ulc::io::write_cloud(same / "1645000000100000.pcd", c);  // us: the same time
  io_test::require_io_error([&] { ulc::io::Sequence s(same.path()); }, {"has the same frame time"});

  io_test::TempDir ms;
  for (int k = 0; k < 3; ++k) ulc::io::write_cloud(ms / ("00000" + std::to_string(k) + ".pcd"), c);
  io_test::write_text(ms / "timestamps.txt", "0\n100\n200\n");
  const ulc::io::Sequence in_ms(ms.path());
  CHECK(in_ms.frame(2).timestamp == Approx(0.2));
  REQUIRE(in_ms.notes().size() == 1);
  CHECK_THAT(in_ms.notes()[0], Catch::Contains("read as milliseconds"));
}
