// RecordingWriter: one interface over our three writers (ROS 1 bag, MCAP, rosbag2 SQLite) for
// point-cloud topics, so tests, benchmarks and tools write the same drive in every storage.
// A .bag holds ROS 1 messages; MCAP and rosbag2 hold CDR (ROS 2) messages.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ulc/bags/cloud_message.hpp"
#include "ulc/bags/compression.hpp"
#include "ulc/bags/mcap_writer.hpp"
#include "ulc/bags/message_definitions.hpp"
#include "ulc/bags/ros1_bag_writer.hpp"
#include "ulc/bags/rosbag2_sqlite_writer.hpp"

namespace ulc::bags {

enum class RecordingKind { ros1_bag, mcap, rosbag2_sqlite };

struct RecordingWriteOptions {
  RecordingKind kind = RecordingKind::ros1_bag;
  Codec compression = Codec::none;  ///< ROS 1: none, bz2, lz4; MCAP: none, zstd, lz4
  bool write_index = true;          ///< ROS 1 index / MCAP summary
};

class RecordingWriter {
 public:
  /// `path`: a .bag or .mcap file, or a rosbag2 folder (created) or .db3 file.
  RecordingWriter(const std::filesystem::path& path, RecordingWriteOptions options)
      : options_(options) {
    switch (options.kind) {
      case RecordingKind::ros1_bag:
        ros1_ = std::make_unique<Ros1BagWriter>(
            path, Ros1WriteOptions{options.compression, 768 * 1024, options.write_index});
        break;
      case RecordingKind::mcap: {
        McapWriteOptions o;
        o.compression = options.compression;
        o.write_summary = options.write_index;
        mcap_ = std::make_unique<McapWriter>(path, o);
        break;
      }
      case RecordingKind::rosbag2_sqlite:
        sqlite_ = std::make_unique<Rosbag2SqliteWriter>(path);
        break;
    }
  }

  Serialization serialization() const {
    return options_.kind == RecordingKind::ros1_bag ? Serialization::ros1 : Serialization::cdr;
  }

  /// A topic of PointCloud2 or Livox CustomMsg messages; returns its handle for write().
  std::size_t add_cloud_topic(const std::string& topic, CloudMessageType type) {
    const bool pc2 = type == CloudMessageType::pointcloud2;
    const bool ros1 = options_.kind == RecordingKind::ros1_bag;
    const std::string type_name =
        pc2 ? (ros1 ? "sensor_msgs/PointCloud2" : "sensor_msgs/msg/PointCloud2")
            : (ros1 ? "livox_ros_driver/CustomMsg" : "livox_ros_driver2/msg/CustomMsg");
    const std::string definition =
        pc2 ? (ros1 ? kPointCloud2Ros1Definition : kPointCloud2Ros2Definition)
            : kLivoxCustomDefinition;
    std::uint64_t id = 0;
    switch (options_.kind) {
      case RecordingKind::ros1_bag:
        id = ros1_->add_connection(
            {topic, type_name, pc2 ? kPointCloud2Md5 : "*", definition, "/ulc", false});
        break;
      case RecordingKind::mcap:
        id = mcap_->add_channel(topic, mcap_->add_schema(type_name, "ros2msg", definition), "cdr");
        break;
      case RecordingKind::rosbag2_sqlite:
        id = static_cast<std::uint64_t>(sqlite_->add_topic(topic, type_name, "cdr"));
        break;
    }
    ids_.push_back(id);
    return ids_.size() - 1;
  }

  /// One message of `topic` received at `receive_ns` (its bytes in this writer's serialization).
  void write(std::size_t topic, std::int64_t receive_ns, const std::vector<unsigned char>& bytes) {
    const std::uint64_t id = ids_.at(topic);
    switch (options_.kind) {
      case RecordingKind::ros1_bag:
        return ros1_->write(static_cast<std::uint32_t>(id), receive_ns, bytes.data(), bytes.size());
      case RecordingKind::mcap:
        return mcap_->write(static_cast<std::uint16_t>(id), receive_ns, receive_ns, bytes.data(),
                            bytes.size());
      case RecordingKind::rosbag2_sqlite:
        return sqlite_->write(static_cast<std::int64_t>(id), receive_ns, bytes.data(),
                              bytes.size());
    }
  }

  void close() {
    if (ros1_) ros1_->close();
    if (mcap_) mcap_->close();
    if (sqlite_) sqlite_->close();
  }

 private:
  RecordingWriteOptions options_;
  std::unique_ptr<Ros1BagWriter> ros1_;
  std::unique_ptr<McapWriter> mcap_;
  std::unique_ptr<Rosbag2SqliteWriter> sqlite_;
  std::vector<std::uint64_t> ids_;
};

}  // namespace ulc::bags
