// std_msgs/Header, as both serialisations store it: ROS 1 has a u32 `seq` before the stamp,
// ROS 2 does not.
#pragma once

#include <cstdint>
#include <string>

#include "ulc/bags/serialization.hpp"

namespace ulc::bags {

struct RosHeader {
  std::int64_t stamp_ns = 0;  ///< header.stamp, nanoseconds since the epoch
  std::string frame_id;
};

inline RosHeader read_header(MessageReader& in, Serialization serialization) {
  RosHeader h;
  if (serialization == Serialization::ros1) (void)in.read<std::uint32_t>("header.seq");
  h.stamp_ns = in.read_time("header.stamp");
  h.frame_id = std::string(in.read_string("header.frame_id"));
  return h;
}

inline void write_header(MessageWriter& out, Serialization serialization, const RosHeader& h) {
  if (serialization == Serialization::ros1) out.write<std::uint32_t>(0);
  out.write_time(h.stamp_ns);
  out.write_string(h.frame_id);
}

}  // namespace ulc::bags
