// livox_ros_driver/CustomMsg and livox_ros_driver2/CustomMsg (same layout in ROS 1 and ROS 2):
//   Header header; uint64 timebase; uint32 point_num; uint8 lidar_id; uint8[3] rsvd;
//   CustomPoint[] points
//   CustomPoint: uint32 offset_time; float32 x, y, z; uint8 reflectivity; uint8 tag; uint8 line
// `offset_time` is nanoseconds after `timebase` (nanoseconds since the epoch).
#pragma once

#include <cstdint>
#include <vector>

#include "ulc/bags/ros_header.hpp"
#include "ulc/bags/serialization.hpp"

namespace ulc::bags {

struct LivoxPoint {
  std::uint32_t offset_time = 0;  ///< nanoseconds after timebase
  float x = 0, y = 0, z = 0;
  std::uint8_t reflectivity = 0, tag = 0, line = 0;
};

struct LivoxCustomMsg {
  RosHeader header;
  std::uint64_t timebase = 0;
  std::uint8_t lidar_id = 0;
  std::vector<LivoxPoint> points;
};

/// Smallest serialised CustomPoint: 4 + 12 + 3 bytes.
constexpr std::size_t kLivoxPointBytes = 19;

inline LivoxCustomMsg parse_livox_custom(MessageReader& in, Serialization serialization) {
  LivoxCustomMsg m;
  m.header = read_header(in, serialization);
  m.timebase = in.read<std::uint64_t>("timebase");
  const std::uint32_t point_num = in.read<std::uint32_t>("point_num");
  m.lidar_id = in.read<std::uint8_t>("lidar_id");
  (void)in.take(3, "rsvd");
  const std::uint32_t n = in.read_count(kLivoxPointBytes, "points");
  if (point_num != n)
    in.fail("point_num " + std::to_string(point_num) + " differs from the " + std::to_string(n) +
            " points the message holds");
  m.points.resize(n);
  for (LivoxPoint& p : m.points) {
    p.offset_time = in.read<std::uint32_t>("points.offset_time");
    p.x = in.read<float>("points.x");
    p.y = in.read<float>("points.y");
    p.z = in.read<float>("points.z");
    p.reflectivity = in.read<std::uint8_t>("points.reflectivity");
    p.tag = in.read<std::uint8_t>("points.tag");
    p.line = in.read<std::uint8_t>("points.line");
  }
  return m;
}

inline std::vector<unsigned char> write_livox_custom(const LivoxCustomMsg& m,
                                                     Serialization serialization,
                                                     io::Endian cdr_order = io::Endian::little) {
  MessageWriter out(serialization, cdr_order);
  write_header(out, serialization, m.header);
  out.write<std::uint64_t>(m.timebase);
  out.write<std::uint32_t>(static_cast<std::uint32_t>(m.points.size()));
  out.write<std::uint8_t>(m.lidar_id);
  for (int k = 0; k < 3; ++k) out.write<std::uint8_t>(0);
  out.write_count(m.points.size());
  for (const LivoxPoint& p : m.points) {
    out.write<std::uint32_t>(p.offset_time);
    out.write<float>(p.x);
    out.write<float>(p.y);
    out.write<float>(p.z);
    out.write<std::uint8_t>(p.reflectivity);
    out.write<std::uint8_t>(p.tag);
    out.write<std::uint8_t>(p.line);
  }
  return out.release();
}

}  // namespace ulc::bags
