// Cloud topics of recordings of every kind: PointCloud2 and Livox CustomMsg written by our
// writers come back through open_recording and CloudTopic with their stamps, points and
// per-point times; the receive time can be the frame time; a missing or non-cloud topic is an
// error naming the point-cloud topics.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "ulc/bags/cloud_encoding.hpp"
#include "ulc/bags/cloud_topic.hpp"
#include "ulc/bags/recording.hpp"
#include "ulc/bags/recording_writer.hpp"

namespace {

namespace fs = std::filesystem;
using ulc::bags::CloudMessageType;
using ulc::bags::RecordingKind;

ulc::io::DecodedCloud frame_cloud(int frame) {
  ulc::io::DecodedCloud c;
  for (int i = 0; i < 200; ++i) {
    c.points.emplace_back(0.25 * i, -0.5 * frame, 0.125 * (i % 5));
    c.intensities.push_back(i % 200);
    c.times.push_back(1e-9 * 250000 * i);  // 0 .. 50 ms, whole nanoseconds
  }
  return c;
}

constexpr std::int64_t kStart = 1700000000000000000;
constexpr std::int64_t kPeriod = 100000000;  // 10 Hz
constexpr std::int64_t kLatency = 3000000;   // received 3 ms after the stamp

/// Three frames on /points (PointCloud2, Ouster `t`) and /livox (CustomMsg), one non-cloud topic.
void write_recording(const fs::path& path, RecordingKind kind) {
  ulc::bags::RecordingWriter w(path, {kind, ulc::bags::Codec::none, true});
  const auto points = w.add_cloud_topic("/points", CloudMessageType::pointcloud2);
  const auto livox = w.add_cloud_topic("/livox", CloudMessageType::livox_custom);
  for (int f = 0; f < 3; ++f) {
    const std::int64_t stamp = kStart + f * kPeriod;
    w.write(points, stamp + kLatency,
            ulc::bags::encode_pointcloud2(frame_cloud(f), stamp, "top", w.serialization(),
                                          ulc::bags::PointTimeStyle::ouster_t));
    w.write(livox, stamp + kLatency,
            ulc::bags::write_livox_custom(ulc::bags::livox_message(frame_cloud(f), stamp, "front"),
                                          w.serialization()));
  }
  w.close();
}

/// One folder per process: CTest runs the test cases as parallel processes.
struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("ulc_test_cloud_topic_" + std::to_string(::getpid()));
  Scratch() {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~Scratch() { fs::remove_all(dir); }
};

}  // namespace

TEST_CASE("cloud topics come back from every kind of recording", "[bags]") {
  const Scratch scratch;
  const struct {
    RecordingKind kind;
    const char* name;
  } kinds[] = {{RecordingKind::ros1_bag, "drive.bag"},
               {RecordingKind::mcap, "drive.mcap"},
               {RecordingKind::rosbag2_sqlite, "rosbag2_drive"}};
  for (const auto& k : kinds) {
    CAPTURE(k.name);
    const fs::path path = scratch.dir / k.name;
    write_recording(path, k.kind);
    const auto rec = ulc::bags::open_recording(path);
    REQUIRE(ulc::bags::cloud_topics(*rec).size() == 2);
    for (const char* topic_name : {"/points", "/livox"}) {
      CAPTURE(topic_name);
      const ulc::bags::CloudTopic topic(*rec, topic_name, path.string());
      auto frames = topic.frames();
      ulc::bags::TopicFrame f;
      for (int i = 0; i < 3; ++i) {
        REQUIRE(frames.next(f));
        const auto expected = frame_cloud(i);
        CHECK(f.message.header.frame_id ==
              (std::string(topic_name) == "/points" ? "top" : "front"));
        CHECK(f.timestamp == static_cast<double>(kStart + i * kPeriod) * 1e-9);
        CHECK(f.receive_time_ns == kStart + i * kPeriod + kLatency);
        REQUIRE(f.message.cloud.size() == expected.size());
        CHECK(f.message.cloud.points == expected.points);
        for (std::size_t p = 0; p < expected.size(); ++p)
          REQUIRE(f.message.cloud.times[p] == Approx(expected.times[p]).margin(1e-12));
      }
      CHECK_FALSE(frames.next(f));
    }
    // The receive time as the frame time: point times move by the latency.
    const ulc::bags::CloudTopic received(*rec, "/points", path.string(),
                                         ulc::bags::FrameTime::receive_time);
    auto frames = received.frames({kStart + kPeriod, kStart + 3 * kPeriod});  // frames 1, 2
    ulc::bags::TopicFrame f;
    REQUIRE(frames.next(f));
    CHECK(f.timestamp == static_cast<double>(kStart + kPeriod + kLatency) * 1e-9);
    CHECK(f.message.cloud.times[0] == Approx(-0.003).margin(1e-12));
    REQUIRE(frames.next(f));
    CHECK_FALSE(frames.next(f));
  }
}

TEST_CASE("a missing or non-cloud topic names the point-cloud topics", "[bags]") {
  const Scratch scratch;
  const fs::path path = scratch.dir / "drive.mcap";
  {
    ulc::bags::McapWriter w(path);
    const auto schema = w.add_schema("std_msgs/msg/String", "ros2msg", "string data\n");
    const auto text = w.add_channel("/chatter", schema, "cdr");
    const unsigned char hello[] = {0, 1, 0, 0, 3, 0, 0, 0, 'h', 'i', 0};
    w.write(text, kStart, kStart, hello, sizeof hello);
    const auto pc2 = w.add_schema("sensor_msgs/msg/PointCloud2", "ros2msg", "");
    const auto points = w.add_channel("/points", pc2, "cdr");
    const auto msg =
        ulc::bags::encode_pointcloud2(frame_cloud(0), kStart, "top", ulc::bags::Serialization::cdr,
                                      ulc::bags::PointTimeStyle::none);
    w.write(points, kStart, kStart, msg.data(), msg.size());
  }
  const auto rec = ulc::bags::open_recording(path);
  REQUIRE_THROWS_WITH(ulc::bags::CloudTopic(*rec, "/nope", path.string()),
                      Catch::Contains("no topic '/nope'") &&
                          Catch::Contains("/points (sensor_msgs/msg/PointCloud2, 1 messages)"));
  REQUIRE_THROWS_WITH(ulc::bags::CloudTopic(*rec, "/chatter", path.string()),
                      Catch::Contains("holds std_msgs/msg/String, not point clouds") &&
                          Catch::Contains(path.string()));
}
