// Point-cloud messages -> io::DecodedCloud with per-point times relative to header.stamp.
//
// Two message types are clouds: sensor_msgs/PointCloud2 (any field layout: x, y, z of any
// numeric type; `intensity`, else `reflectivity`; the time field chosen as for files,
// io::kTimeFieldNames, its convention decided by point_time.hpp) and the Livox CustomMsg of
// livox_ros_driver and livox_ros_driver2. Points with a non-finite coordinate (the NaN padding
// of organised clouds) are dropped and counted.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "ulc/bags/livox_custom.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/bags/point_time.hpp"
#include "ulc/bags/pointcloud2.hpp"
#include "ulc/io/decoded_cloud.hpp"
#include "ulc/io/field_roles.hpp"
#include "ulc/io/read_stats.hpp"

namespace ulc::bags {

enum class CloudMessageType { pointcloud2, livox_custom };

/// The cloud type a message type names ("sensor_msgs/PointCloud2", "sensor_msgs/msg/PointCloud2",
/// "livox_ros_driver2/msg/CustomMsg", ...), or nullopt when it is not a cloud.
inline std::optional<CloudMessageType> cloud_message_type(std::string type) {
  if (const auto at = type.find("/msg/"); at != std::string::npos) type.erase(at, 4);
  if (type == "sensor_msgs/PointCloud2") return CloudMessageType::pointcloud2;
  if (type == "livox_ros_driver/CustomMsg" || type == "livox_ros_driver2/CustomMsg")
    return CloudMessageType::livox_custom;
  return std::nullopt;
}

struct CloudMessage {
  RosHeader header;
  io::DecodedCloud cloud;  ///< per-point times in seconds relative to header.stamp
  PointTimeInfo time;      ///< where they came from
  io::ReadStats stats;     ///< fields, intensity field, counts (format "PointCloud2"/"CustomMsg")
};

namespace detail {

struct FieldAt {
  std::uint32_t offset = 0;
  io::ScalarType type = io::ScalarType::float32;
};

inline std::optional<FieldAt> scalar_field(const PointCloud2View& c, const char* name) {
  const PointField* f = c.field(name);
  if (!f || f->count != 1) return std::nullopt;
  return FieldAt{f->offset, f->type};
}

inline FieldAt required_field(const PointCloud2View& c, const char* name, MessageReader& in) {
  const auto f = scalar_field(c, name);
  if (!f) in.fail(std::string("no field '") + name + "' of count 1 (x, y and z are required)");
  return *f;
}

inline double value_at(const unsigned char* point, FieldAt f, io::Endian order) {
  return io::decode_scalar(point + f.offset, f.type, order);
}

/// The first present time field of io::kTimeFieldNames.
inline std::optional<FieldAt> time_field(const PointCloud2View& c, PointTimeInfo& info) {
  for (const char* name : io::kTimeFieldNames)
    if (const auto f = scalar_field(c, name)) {
      info.field = name;
      info.type = f->type;
      return f;
    }
  return std::nullopt;
}

inline void finish_times(CloudMessage& out, MessageReader& in) {
  const double stamp_s = static_cast<double>(out.header.stamp_ns) * 1e-9;
  if (!resolve_point_times(out.cloud.times, stamp_s, out.time))
    in.fail("per-point time field '" + out.time.field + "' holds values that are neither " +
            "near header.stamp nor offsets within a sweep: its unit cannot be told");
  out.stats.time_field = out.time.reference == TimeReference::none ? "" : out.time.field;
  out.stats.time_scale = out.time.seconds_per_unit;
}

inline CloudMessage decode_pointcloud2(MessageReader& in, Serialization serialization) {
  const PointCloud2View c = parse_pointcloud2(in, serialization);
  const FieldAt x = required_field(c, "x", in), y = required_field(c, "y", in),
                z = required_field(c, "z", in);
  CloudMessage out;
  out.header = c.header;
  auto intensity = scalar_field(c, "intensity");
  if (!intensity) intensity = scalar_field(c, "reflectivity");
  const auto time = time_field(c, out.time);
  io::DecodedBuilder builder(c.point_count(), intensity.has_value(), time.has_value());
  for (std::size_t i = 0, n = c.point_count(); i < n; ++i) {
    const unsigned char* p = c.point(i);
    builder.add(value_at(p, x, c.order), value_at(p, y, c.order), value_at(p, z, c.order),
                intensity ? value_at(p, *intensity, c.order) : 0.0,
                time ? value_at(p, *time, c.order) : 0.0);
  }
  out.cloud = builder.finish(out.stats);
  out.stats.format = "PointCloud2";
  out.stats.encoding = c.order == io::Endian::big ? "big endian" : "little endian";
  for (const PointField& f : c.fields) out.stats.fields.push_back(f.name);
  if (intensity) out.stats.intensity_field = c.field("intensity") ? "intensity" : "reflectivity";
  out.stats.width = c.width;
  out.stats.height = c.height;
  out.stats.points_in_file = c.point_count();
  if (time) finish_times(out, in);
  return out;
}

inline CloudMessage decode_livox(MessageReader& in, Serialization serialization) {
  const LivoxCustomMsg m = parse_livox_custom(in, serialization);
  CloudMessage out;
  out.header = m.header;
  out.time.field = "offset_time";
  out.time.type = io::ScalarType::uint32;
  io::DecodedBuilder builder(m.points.size(), true, true);
  // offset_time counts from timebase: as nanoseconds relative to the stamp they stay exact. A
  // timebase in another clock than the stamp (seconds away) cannot be related to it: the
  // offsets are then taken from the stamp, and the note says so.
  // The gap is first taken in double: a corrupted or foreign timebase (any uint64) must not
  // overflow; within the sweep limit both values are small enough to subtract exactly.
  const double gap_ns = static_cast<double>(m.timebase) - static_cast<double>(m.header.stamp_ns);
  double base_ns = 0.0;
  if (std::abs(gap_ns) > kMaxSweepSeconds * 1e9) {
    out.time.note = "timebase is " + std::to_string(gap_ns * 1e-9) +
                    " s from header.stamp (another clock): offsets taken from the stamp";
  } else {
    base_ns = static_cast<double>(static_cast<std::int64_t>(m.timebase) - m.header.stamp_ns);
  }
  for (const LivoxPoint& p : m.points)
    builder.add(p.x, p.y, p.z, p.reflectivity, (base_ns + p.offset_time) * 1e-9);
  out.cloud = builder.finish(out.stats);
  out.stats.format = "CustomMsg";
  out.stats.encoding = "Livox";
  out.stats.fields = {"offset_time", "x", "y", "z", "reflectivity", "tag", "line"};
  out.stats.intensity_field = "reflectivity";
  out.stats.width = m.points.size();
  out.stats.height = 1;
  out.stats.points_in_file = m.points.size();
  out.time.reference = TimeReference::relative;
  out.time.seconds_per_unit = 1e-9;
  out.stats.time_field = "offset_time";
  out.stats.time_scale = 1e-9;
  return out;
}

}  // namespace detail

/// Decodes one cloud message of a topic whose type cloud_message_type() recognised.
inline CloudMessage decode_cloud_message(CloudMessageType type, const TopicInfo& topic,
                                         const MessageView& message) {
  MessageReader in(message, topic.serialization, topic.type);
  return type == CloudMessageType::pointcloud2 ? detail::decode_pointcloud2(in, topic.serialization)
                                               : detail::decode_livox(in, topic.serialization);
}

}  // namespace ulc::bags
