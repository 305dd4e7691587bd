// Uses the installed recording readers (COMPONENTS bags): writes a one-message ROS 1 bag of a
// PointCloud2 and reads the cloud back.
#include <cstdio>
#include <filesystem>

#include "ulc/bags/cloud_encoding.hpp"
#include "ulc/bags/cloud_topic.hpp"
#include "ulc/bags/recording.hpp"
#include "ulc/bags/recording_writer.hpp"

int main() {
  const auto file = std::filesystem::temp_directory_path() / "ulc_consumer_bags.bag";
  ulc::io::DecodedCloud cloud;
  cloud.points = {{1, 2, 3}, {4, 5, 6}};
  {
    ulc::bags::RecordingWriter writer(file, {});
    const auto topic = writer.add_cloud_topic("/points", ulc::bags::CloudMessageType::pointcloud2);
    writer.write(topic, 1000000000,
                 ulc::bags::encode_pointcloud2(cloud, 1000000000, "lidar", writer.serialization(),
                                               ulc::bags::PointTimeStyle::none));
  }
  const auto recording = ulc::bags::open_recording(file);
  const ulc::bags::CloudTopic topic(*recording, "/points", file.string());
  auto frames = topic.frames();
  ulc::bags::TopicFrame frame;
  const bool ok = frames.next(frame) && frame.message.cloud.points == cloud.points &&
                  frame.message.header.frame_id == "lidar";
  std::filesystem::remove(file);
  std::printf("consumer_bags: %s\n", ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
