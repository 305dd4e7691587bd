// Writes a dataset folder (the simulator's output) as a recording: every LiDAR's frames as a
// topic /<lidar>/points of PointCloud2 messages (frame_id <lidar>, header.stamp the frame time,
// Velodyne-style float32 `time` relative to it), received at the stamp. The LiDARs are written one
// after the other, so the recording's messages are not in time order in the file.
#pragma once

#include <cmath>
#include <filesystem>
#include <string>

#include "ulc/bags/cloud_encoding.hpp"
#include "ulc/bags/recording_writer.hpp"
#include "ulc/io/sequence.hpp"

namespace ulc_test {

inline void write_dataset_as_recording(const std::filesystem::path& dataset,
                                       const std::filesystem::path& out,
                                       ulc::bags::RecordingWriteOptions options) {
  ulc::bags::RecordingWriter writer(out, options);
  for (const auto& folder : ulc::io::list_lidar_folders(dataset)) {
    const ulc::io::Sequence seq(folder);
    const std::size_t topic = writer.add_cloud_topic("/" + seq.name() + "/points",
                                                     ulc::bags::CloudMessageType::pointcloud2);
    for (std::size_t i = 0; i < seq.size(); ++i) {
      const auto stamp = static_cast<std::int64_t>(std::llround(seq.frame(i).timestamp * 1e9));
      writer.write(topic, stamp,
                   ulc::bags::encode_pointcloud2(seq.load_decoded(i), stamp, seq.name(),
                                                 writer.serialization(),
                                                 ulc::bags::PointTimeStyle::velodyne_time));
    }
  }
  writer.close();
}

}  // namespace ulc_test
