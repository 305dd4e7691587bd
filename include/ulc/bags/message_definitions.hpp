// The message definitions our writers store with each topic (ROS 1 connection headers, MCAP
// schemas), so other tools can read the bags ULC writes. Readers never need them: ULC decodes
// the two cloud types it knows by their type names.
#pragma once

#include <string>

namespace ulc::bags {

namespace definitions_detail {

inline constexpr const char* kSeparator =
    "================================================================================\n";

/// PointCloud2's own fields; `header_type` is how each ROS spells the header's type.
inline std::string pointcloud2_fields(const char* header_type) {
  return std::string(header_type) +
         " header\n"
         "uint32 height\n"
         "uint32 width\n"
         "PointField[] fields\n"
         "bool    is_bigendian\n"
         "uint32  point_step\n"
         "uint32  row_step\n"
         "uint8[] data\n"
         "bool is_dense\n"
         "\n";
}

inline constexpr const char* kPointField =
    "MSG: sensor_msgs/PointField\n"
    "uint8 INT8    = 1\n"
    "uint8 UINT8   = 2\n"
    "uint8 INT16   = 3\n"
    "uint8 UINT16  = 4\n"
    "uint8 INT32   = 5\n"
    "uint8 UINT32  = 6\n"
    "uint8 FLOAT32 = 7\n"
    "uint8 FLOAT64 = 8\n"
    "string name\n"
    "uint32 offset\n"
    "uint8  datatype\n"
    "uint32 count\n";

}  // namespace definitions_detail

/// sensor_msgs/PointCloud2's MD5 as ROS 1 computes it from the definition.
inline constexpr const char* kPointCloud2Md5 = "1158d486dd51d683ce2f1be655c3c181";

/// ROS 1 full text (the message, then each type it uses after a line of '=').
inline const std::string kPointCloud2Ros1Definition =
    definitions_detail::pointcloud2_fields("Header") + definitions_detail::kSeparator +
    "MSG: std_msgs/Header\n"
    "uint32 seq\n"
    "time stamp\n"
    "string frame_id\n"
    "\n" +
    definitions_detail::kSeparator + definitions_detail::kPointField;

/// ROS 2 ("ros2msg" schema encoding).
inline const std::string kPointCloud2Ros2Definition =
    definitions_detail::pointcloud2_fields("std_msgs/Header") + definitions_detail::kSeparator +
    "MSG: std_msgs/Header\n"
    "builtin_interfaces/Time stamp\n"
    "string frame_id\n"
    "\n" +
    definitions_detail::kSeparator +
    "MSG: builtin_interfaces/Time\n"
    "int32 sec\n"
    "uint32 nanosec\n"
    "\n" +
    definitions_detail::kSeparator + definitions_detail::kPointField;

/// livox_ros_driver/CustomMsg (ROS 1; ROS 2's livox_ros_driver2 has the same fields). Its MD5 is
/// written as "*" (any), which ROS 1 tools accept.
inline constexpr const char* kLivoxCustomDefinition =
    "Header header\n"
    "uint64 timebase\n"
    "uint32 point_num\n"
    "uint8 lidar_id\n"
    "uint8[3] rsvd\n"
    "CustomPoint[] points\n"
    "\n"
    "================================================================================\n"
    "MSG: livox_ros_driver/CustomPoint\n"
    "uint32 offset_time\n"
    "float32 x\n"
    "float32 y\n"
    "float32 z\n"
    "uint8 reflectivity\n"
    "uint8 tag\n"
    "uint8 line\n";

}  // namespace ulc::bags
