// Fuzzes the point-cloud message decoders (ulc/bags/cloud_message.hpp): sensor_msgs/PointCloud2
// and the Livox CustomMsg, each in ROS 1 and CDR serialisation. The first input byte picks the
// variant (bit 0: CDR, bit 1: Livox); the rest is the message.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "ulc/bags/cloud_message.hpp"

namespace {

ulc::bags::TopicInfo topic_for(std::uint8_t variant) {
  const bool cdr = (variant & 1) != 0;
  const bool livox = (variant & 2) != 0;
  ulc::bags::TopicInfo topic;
  topic.name = "/points";
  topic.serialization = cdr ? ulc::bags::Serialization::cdr : ulc::bags::Serialization::ros1;
  if (livox)
    topic.type = cdr ? "livox_ros_driver2/msg/CustomMsg" : "livox_ros_driver/CustomMsg";
  else
    topic.type = cdr ? "sensor_msgs/msg/PointCloud2" : "sensor_msgs/PointCloud2";
  return topic;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const ulc::bags::TopicInfo topic = topic_for(data[0]);
  const auto type = ulc::bags::cloud_message_type(topic.type);
  ulc_fuzz::fuzz_require(type.has_value(), "a cloud type name was not recognised");
  static const std::string file = "fuzz message";
  ulc::bags::MessageView message;
  message.data = data + 1;
  message.size = size - 1;
  message.file = &file;
  try {
    const ulc::bags::CloudMessage cloud = ulc::bags::decode_cloud_message(*type, topic, message);
    ulc_fuzz::check_decoded(cloud.cloud);
    ulc_fuzz::fuzz_require(
        cloud.stats.points_read + cloud.stats.points_dropped_nonfinite ==
            cloud.stats.points_in_file,
        "cloud message: points read + dropped differ from the points in the message");
  } catch (const ulc::io::IoError&) {
    // A refused message: the expected outcome for most inputs.
  }
  return 0;
}
