// sensor_msgs/PointCloud2 in both serialisations: every field layout read back exactly.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "ulc/bags/cloud_encoding.hpp"
#include "ulc/bags/cloud_message.hpp"

namespace {

using ulc::bags::Serialization;
using ulc::io::Endian;
using ulc::io::ScalarType;

const std::string kFile = "memory.bag";

ulc::bags::MessageView view_of(const std::vector<unsigned char>& bytes, std::uint64_t offset = 0) {
  ulc::bags::MessageView m;
  m.data = bytes.data();
  m.size = bytes.size();
  m.file = &kFile;
  m.offset = offset;
  return m;
}

ulc::bags::TopicInfo pc2_topic(Serialization s) {
  ulc::bags::TopicInfo t;
  t.name = "/points";
  t.type = s == Serialization::ros1 ? "sensor_msgs/PointCloud2" : "sensor_msgs/msg/PointCloud2";
  t.serialization = s;
  return t;
}

ulc::bags::CloudMessage decode(const std::vector<unsigned char>& bytes, Serialization s) {
  return ulc::bags::decode_cloud_message(ulc::bags::CloudMessageType::pointcloud2, pc2_topic(s),
                                         view_of(bytes));
}

/// A sweep of n points over 0.1 s with intensities; coordinates are multiples of 1/64, exact in
/// float32 as a float32 file would hold them.
ulc::io::DecodedCloud sweep(std::size_t n) {
  ulc::io::DecodedCloud c;
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = static_cast<double>(i);
    c.points.emplace_back(std::fmod(k, 97.0) / 64.0 - 0.75, std::fmod(k * 7, 89.0) / 64.0,
                          std::fmod(k, 7.0) / 64.0);
    c.intensities.push_back(std::fmod(k, 100.0));
    c.times.push_back(static_cast<float>(0.1 * k / static_cast<double>(n)));
  }
  return c;
}

constexpr std::int64_t kStamp = 1700000000123456789;

}  // namespace

TEST_CASE("PointCloud2: points, intensities and every time convention come back", "[bags]") {
  using Style = ulc::bags::PointTimeStyle;
  const ulc::io::DecodedCloud cloud = sweep(500);
  struct Case {
    Style style;
    const char* field;
    ulc::bags::TimeReference reference;
    double tolerance;  // seconds: float32 seconds, integer nanoseconds, float64 absolute seconds
  };
  const Case cases[] = {
      {Style::velodyne_time, "time", ulc::bags::TimeReference::relative, 0.0},
      {Style::ouster_t, "t", ulc::bags::TimeReference::relative, 1e-9},
      {Style::livox_offset_time, "offset_time", ulc::bags::TimeReference::relative, 1e-9},
      {Style::hesai_timestamp, "timestamp", ulc::bags::TimeReference::absolute, 1e-6},
  };
  for (const Serialization s : {Serialization::ros1, Serialization::cdr}) {
    for (const Case& c : cases) {
      CAPTURE(static_cast<int>(s), c.field);
      const auto bytes = ulc::bags::encode_pointcloud2(cloud, kStamp, "lidar_top", s, c.style);
      const auto msg = decode(bytes, s);
      REQUIRE(msg.header.stamp_ns == kStamp);
      REQUIRE(msg.header.frame_id == "lidar_top");
      REQUIRE(msg.cloud.size() == cloud.size());
      REQUIRE(msg.time.field == c.field);
      REQUIRE(msg.time.reference == c.reference);
      for (std::size_t i = 0; i < cloud.size(); ++i) {
        REQUIRE(msg.cloud.points[i] == cloud.points[i]);  // float32 in, float32 out
        REQUIRE(msg.cloud.intensities[i] == cloud.intensities[i]);
        REQUIRE(std::abs(msg.cloud.times[i] - cloud.times[i]) <= c.tolerance);
      }
    }
  }
}

TEST_CASE("PointCloud2: CDR of either byte order, big-endian point data", "[bags]") {
  const ulc::io::DecodedCloud cloud = sweep(64);
  for (const Endian cdr : {Endian::little, Endian::big}) {
    for (const Endian data : {Endian::little, Endian::big}) {
      ulc::bags::PointCloud2View layout;
      const auto bytes = ulc::bags::encode_pointcloud2(cloud, kStamp, "f", Serialization::cdr,
                                                       ulc::bags::PointTimeStyle::ouster_t, data);
      // Re-serialise the same layout with the CDR byte order under test.
      const ulc::bags::MessageView m = view_of(bytes);
      ulc::bags::MessageReader in(m, Serialization::cdr, "sensor_msgs/msg/PointCloud2");
      const auto parsed = ulc::bags::parse_pointcloud2(in, Serialization::cdr);
      const auto again = ulc::bags::write_pointcloud2(parsed, Serialization::cdr, cdr);
      REQUIRE(again[1] == (cdr == Endian::little ? 1 : 0));
      const auto msg = decode(again, Serialization::cdr);
      REQUIRE(msg.stats.encoding == (data == Endian::big ? "big endian" : "little endian"));
      REQUIRE(msg.cloud.size() == cloud.size());
      for (std::size_t i = 0; i < cloud.size(); ++i) {
        REQUIRE(msg.cloud.points[i] == cloud.points[i]);
        REQUIRE(std::abs(msg.cloud.times[i] - cloud.times[i]) <= 1e-9);
      }
    }
  }
}

TEST_CASE("PointCloud2: any layout - every datatype, padding, organised, NaN padding", "[bags]") {
  // An organised 3 x 4 cloud: x int16 (cm), y float64, z uint8, intensity uint16, t float32,
  // with padding bytes, an unused 3-count field and row padding; one NaN point per row.
  ulc::bags::PointCloud2View c;
  c.header = {kStamp, "organised"};
  c.height = 3;
  c.width = 4;
  c.fields = {{"pad", 0, ScalarType::int32, 3},         {"x", 12, ScalarType::int16, 1},
              {"y", 16, ScalarType::float64, 1},        {"z", 24, ScalarType::uint8, 1},
              {"intensity", 26, ScalarType::uint16, 1}, {"time", 28, ScalarType::float32, 1}};
  c.point_step = 40;
  c.row_step = 4 * 40 + 8;
  std::vector<unsigned char> data(c.height * c.row_step, 0xAB);
  for (std::uint32_t r = 0; r < 3; ++r)
    for (std::uint32_t k = 0; k < 4; ++k) {
      unsigned char* p = data.data() + r * c.row_step + k * c.point_step;
      const double y = k == 3 ? std::numeric_limits<double>::quiet_NaN() : 0.5 * r + k;
      ulc::io::store<std::int16_t>(p + 12, static_cast<std::int16_t>(-100 * (int)k),
                                   Endian::little);
      ulc::io::store<double>(p + 16, y, Endian::little);
      p[24] = static_cast<unsigned char>(r);
      ulc::io::store<std::uint16_t>(p + 26, static_cast<std::uint16_t>(1000 + k), Endian::little);
      ulc::io::store<float>(p + 28, 0.01f * static_cast<float>(k), Endian::little);
    }
  c.data = data.data();
  c.data_size = data.size();
  for (const Serialization s : {Serialization::ros1, Serialization::cdr}) {
    const auto msg = decode(ulc::bags::write_pointcloud2(c, s), s);
    REQUIRE(msg.stats.points_in_file == 12);
    REQUIRE(msg.stats.points_dropped_nonfinite == 3);
    REQUIRE(msg.stats.height == 3);
    REQUIRE(msg.cloud.size() == 9);
    std::size_t i = 0;
    for (std::uint32_t r = 0; r < 3; ++r)
      for (std::uint32_t k = 0; k < 3; ++k, ++i) {
        REQUIRE(msg.cloud.points[i].x() == -100.0 * k);
        REQUIRE(msg.cloud.points[i].y() == 0.5 * r + k);
        REQUIRE(msg.cloud.points[i].z() == r);
        REQUIRE(msg.cloud.intensities[i] == 1000 + k);
        REQUIRE(msg.cloud.times[i] == static_cast<double>(0.01f * static_cast<float>(k)));
      }
  }
}

TEST_CASE("PointCloud2: layouts that do not fit their data are errors", "[bags]") {
  const ulc::io::DecodedCloud cloud = sweep(10);
  const auto good = ulc::bags::encode_pointcloud2(cloud, kStamp, "f", Serialization::ros1,
                                                  ulc::bags::PointTimeStyle::velodyne_time);
  ulc::bags::MessageView m = view_of(good);
  ulc::bags::MessageReader in(m, Serialization::ros1, "sensor_msgs/PointCloud2");
  ulc::bags::PointCloud2View c = ulc::bags::parse_pointcloud2(in, Serialization::ros1);
  auto expect_error = [](ulc::bags::PointCloud2View bad, const char* words) {
    const auto bytes = ulc::bags::write_pointcloud2(bad, Serialization::ros1);
    REQUIRE_THROWS_WITH(decode(bytes, Serialization::ros1),
                        Catch::Contains(words) && Catch::Contains("memory.bag"));
  };
  auto wide = c;
  wide.fields[0].offset = c.point_step - 2;  // x runs past the point
  expect_error(wide, "past point_step");
  auto tall = c;
  tall.height = 2;  // two rows, data for one
  expect_error(tall, "bytes of data");
  auto narrow = c;
  narrow.row_step = c.point_step;  // rows overlap
  expect_error(narrow, "row_step");
  auto no_z = c;
  no_z.fields[2].name = "w";
  expect_error(no_z, "no field 'z'");
}

TEST_CASE("PointCloud2: a message cut or corrupted anywhere is one clear error", "[bags]") {
  const ulc::io::DecodedCloud cloud = sweep(20);
  for (const Serialization s : {Serialization::ros1, Serialization::cdr}) {
    const auto good =
        ulc::bags::encode_pointcloud2(cloud, kStamp, "f", s, ulc::bags::PointTimeStyle::ouster_t);
    for (std::size_t cut = 0; cut < good.size(); ++cut) {
      const std::vector<unsigned char> part(good.begin(), good.begin() + cut);
      try {
        (void)decode(part, s);
        FAIL("a message cut at byte " << cut << " decoded");
      } catch (const ulc::io::IoError& e) {
        REQUIRE(e.file() == "memory.bag");
        REQUIRE(e.position() == "byte 0");
      }
    }
    for (std::size_t at = 0; at < good.size(); ++at) {
      for (const unsigned char flip : {0x01, 0x80, 0xFF}) {
        auto bad = good;
        bad[at] = static_cast<unsigned char>(bad[at] ^ flip);
        try {
          (void)decode(bad, s);
        } catch (const ulc::io::IoError&) {
        }
      }
    }
  }
}

TEST_CASE("PointCloud2: huge counts fail before any allocation", "[bags]") {
  const ulc::io::DecodedCloud cloud = sweep(4);
  const auto good = ulc::bags::encode_pointcloud2(cloud, kStamp, "f", Serialization::ros1,
                                                  ulc::bags::PointTimeStyle::none);
  // ROS 1 layout: seq 4, stamp 8, frame_id 4 + 1, height 4, width 4, fields count at byte 25.
  auto bad = good;
  ulc::io::store<std::uint32_t>(bad.data() + 25, 0xFFFFFFFFu, Endian::little);
  REQUIRE_THROWS_WITH(decode(bad, Serialization::ros1), Catch::Contains("claims 4294967295"));
  bad = good;
  ulc::io::store<std::uint32_t>(bad.data() + 12, 0xFFFFFFF0u, Endian::little);  // frame_id
  REQUIRE_THROWS_WITH(decode(bad, Serialization::ros1), Catch::Contains("header.frame_id"));
}
