// CloudTopic: the frames of one LiDAR in a recording, decoded one at a time.
//
// A frame's time is the message's header.stamp (FrameTime::header_stamp, the default: the
// driver's time of the sweep) or the time the recorder received it (FrameTime::receive_time);
// per-point times are relative to that frame time either way. A topic that is missing or is not
// a point cloud is an IoError that lists the point-cloud topics the recording has.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "ulc/bags/cloud_message.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

enum class FrameTime { header_stamp, receive_time };

struct TopicFrame {
  CloudMessage message;    ///< the decoded cloud; its times are relative to `timestamp`
  double timestamp = 0.0;  ///< seconds since the epoch: header.stamp or the receive time
  std::int64_t receive_time_ns = 0;
};

/// The topics whose messages are clouds.
inline std::vector<TopicInfo> cloud_topics(const MessageSource& source) {
  std::vector<TopicInfo> out;
  for (const TopicInfo& t : source.topics())
    if (cloud_message_type(t.type)) out.push_back(t);
  return out;
}

/// "/velodyne_points (sensor_msgs/PointCloud2, 600 messages), ..." or "none".
inline std::string describe_cloud_topics(const MessageSource& source) {
  std::string out;
  for (const TopicInfo& t : cloud_topics(source))
    out += (out.empty() ? "" : ", ") + t.name + " (" + t.type + ", " +
           std::to_string(t.message_count) + " messages)";
  return out.empty() ? "none" : out;
}

class CloudTopic {
 public:
  /// `file` names the recording in errors.
  CloudTopic(const MessageSource& source, const std::string& topic, const std::string& file,
             FrameTime frame_time = FrameTime::header_stamp)
      : source_(source), frame_time_(frame_time) {
    const auto& topics = source.topics();
    index_ = topics.size();
    for (std::size_t i = 0; i < topics.size(); ++i)
      if (topics[i].name == topic) index_ = i;
    if (index_ == topics.size())
      throw io::IoError(
          file, "",
          "no topic '" + topic + "'; its point-cloud topics: " + describe_cloud_topics(source));
    const auto type = cloud_message_type(topics[index_].type);
    if (!type)
      throw io::IoError(
          file, "",
          "topic '" + topic + "' holds " + topics[index_].type +
              ", not point clouds; its point-cloud topics: " + describe_cloud_topics(source));
    type_ = *type;
  }

  const TopicInfo& info() const { return source_.topics()[index_]; }
  CloudMessageType type() const { return type_; }

  class Cursor {
   public:
    Cursor(const CloudTopic& topic, std::unique_ptr<MessageCursor> messages)
        : topic_(topic), messages_(std::move(messages)) {}
    /// The next frame, or false at the end of the selection.
    bool next(TopicFrame& out) {
      MessageView m;
      if (!messages_->next(m)) return false;
      out.message = decode_cloud_message(topic_.type_, topic_.info(), m);
      out.receive_time_ns = m.time_ns;
      const std::int64_t stamp_ns = out.message.header.stamp_ns;
      if (topic_.frame_time_ == FrameTime::receive_time) {
        const double shift = static_cast<double>(stamp_ns - m.time_ns) * 1e-9;
        for (double& t : out.message.cloud.times) t += shift;
        out.timestamp = static_cast<double>(m.time_ns) * 1e-9;
      } else {
        out.timestamp = static_cast<double>(stamp_ns) * 1e-9;
      }
      return true;
    }

   private:
    const CloudTopic& topic_;
    std::unique_ptr<MessageCursor> messages_;
  };

  /// The frames received within `window`, in receive order.
  Cursor frames(TimeWindow window = {}) const {
    return Cursor(*this, source_.cursor({index_}, window));
  }

 private:
  const MessageSource& source_;
  FrameTime frame_time_;
  std::size_t index_ = 0;
  CloudMessageType type_ = CloudMessageType::pointcloud2;
};

}  // namespace ulc::bags
