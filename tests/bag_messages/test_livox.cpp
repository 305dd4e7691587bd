// Livox CustomMsg (livox_ros_driver and livox_ros_driver2) in both serialisations.
#include <catch2/catch.hpp>
#include <limits>
#include <string>
#include <vector>

#include "ulc/bags/cloud_encoding.hpp"
#include "ulc/bags/cloud_message.hpp"

namespace {

const std::string kLivoxFile = "livox.mcap";

ulc::bags::CloudMessage decode_livox_bytes(const std::vector<unsigned char>& bytes,
                                           ulc::bags::Serialization s, const char* type) {
  ulc::bags::MessageView m;
  m.data = bytes.data();
  m.size = bytes.size();
  m.file = &kLivoxFile;
  ulc::bags::TopicInfo t;
  t.type = type;
  t.serialization = s;
  const auto kind = ulc::bags::cloud_message_type(type);
  REQUIRE(kind == ulc::bags::CloudMessageType::livox_custom);
  return ulc::bags::decode_cloud_message(*kind, t, m);
}

}  // namespace

TEST_CASE("Livox CustomMsg: points and offset times come back", "[bags]") {
  ulc::io::DecodedCloud cloud;
  for (int i = 0; i < 300; ++i) {
    cloud.points.emplace_back(static_cast<float>(i) * 0.5f, -1.25f,
                              0.125f * static_cast<float>(i % 9));
    cloud.intensities.push_back(i % 256);
    cloud.times.push_back(1e-9 * 333333.0 * i);
  }
  const std::int64_t stamp = 1650000000000000000;
  const struct {
    ulc::bags::Serialization s;
    const char* type;
  } kinds[] = {{ulc::bags::Serialization::ros1, "livox_ros_driver/CustomMsg"},
               {ulc::bags::Serialization::cdr, "livox_ros_driver2/msg/CustomMsg"},
               {ulc::bags::Serialization::ros1, "livox_ros_driver2/CustomMsg"}};
  for (const auto& k : kinds) {
    CAPTURE(k.type);
    const auto m = ulc::bags::livox_message(cloud, stamp, "livox_frame");
    const auto msg = decode_livox_bytes(ulc::bags::write_livox_custom(m, k.s), k.s, k.type);
    REQUIRE(msg.header.frame_id == "livox_frame");
    REQUIRE(msg.cloud.size() == cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      REQUIRE(msg.cloud.points[i] == cloud.points[i]);
      REQUIRE(msg.cloud.intensities[i] == cloud.intensities[i]);
      REQUIRE(msg.cloud.times[i] == Approx(cloud.times[i]).margin(1e-9));
    }
  }
}

TEST_CASE("Livox CustomMsg: a timebase after the stamp shifts the times; lies are errors",
          "[bags]") {
  ulc::io::DecodedCloud cloud;
  cloud.points = {{1, 2, 3}, {4, 5, 6}};
  cloud.times = {0.0, 0.01};
  auto m = ulc::bags::livox_message(cloud, 1000000000, "f");
  m.timebase += 2000000;  // 2 ms after the stamp
  auto msg = decode_livox_bytes(ulc::bags::write_livox_custom(m, ulc::bags::Serialization::ros1),
                                ulc::bags::Serialization::ros1, "livox_ros_driver/CustomMsg");
  REQUIRE(msg.cloud.times[0] == Approx(0.002).margin(1e-12));
  REQUIRE(msg.cloud.times[1] == Approx(0.012).margin(1e-12));

  // A timebase in another clock (here the largest uint64) is not related to the stamp: the
  // offsets count from the stamp, and the time field says so.
  auto foreign = m;
  foreign.timebase = std::numeric_limits<std::uint64_t>::max();
  const auto far =
      decode_livox_bytes(ulc::bags::write_livox_custom(foreign, ulc::bags::Serialization::ros1),
                         ulc::bags::Serialization::ros1, "livox_ros_driver/CustomMsg");
  REQUIRE(far.cloud.times[1] == Approx(0.01).margin(1e-12));
  REQUIRE_THAT(ulc::bags::describe(far.time), Catch::Contains("another clock"));

  auto bytes = ulc::bags::write_livox_custom(m, ulc::bags::Serialization::ros1);
  // point_num sits after seq 4, stamp 8, frame_id 4 + 1, timebase 8 = byte 25.
  ulc::io::store<std::uint32_t>(bytes.data() + 25, 7u, ulc::io::Endian::little);
  REQUIRE_THROWS_WITH(
      decode_livox_bytes(bytes, ulc::bags::Serialization::ros1, "livox_ros_driver/CustomMsg"),
      Catch::Contains("point_num 7"));
  const auto cdr = ulc::bags::write_livox_custom(m, ulc::bags::Serialization::cdr);
  for (std::size_t cut = 0; cut < cdr.size(); ++cut) {
    const std::vector<unsigned char> part(cdr.begin(), cdr.begin() + cut);
    REQUIRE_THROWS_AS(
        decode_livox_bytes(part, ulc::bags::Serialization::cdr, "livox_ros_driver2/msg/CustomMsg"),
        ulc::io::IoError);
  }
}

TEST_CASE("cloud message types are recognised by name in both ROS spellings", "[bags]") {
  REQUIRE(ulc::bags::cloud_message_type("sensor_msgs/PointCloud2"));
  REQUIRE(ulc::bags::cloud_message_type("sensor_msgs/msg/PointCloud2"));
  REQUIRE(ulc::bags::cloud_message_type("livox_ros_driver/msg/CustomMsg"));
  REQUIRE_FALSE(ulc::bags::cloud_message_type("sensor_msgs/PointCloud"));
  REQUIRE_FALSE(ulc::bags::cloud_message_type("std_msgs/msg/String"));
}
