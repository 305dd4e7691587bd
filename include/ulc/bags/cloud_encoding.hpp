// Clouds -> point-cloud messages, as the common drivers publish them: the writing side of
// cloud_message.hpp, for our bag writers (tests, benchmarks, conversions).
//
// PointTimeStyle picks the per-point time field a driver would write:
//   velodyne_time      `time`        float32 seconds relative to the stamp
//   ouster_t           `t`           uint32 nanoseconds relative to the stamp
//   livox_offset_time  `offset_time` uint32 nanoseconds relative to the stamp
//   hesai_timestamp    `timestamp`   float64 absolute seconds
// Points are x, y, z float32 (plus `intensity` float32), so a cloud read from a float32 file
// comes back from the message with the very same numbers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "ulc/bags/livox_custom.hpp"
#include "ulc/bags/pointcloud2.hpp"
#include "ulc/io/decoded_cloud.hpp"

namespace ulc::bags {

enum class PointTimeStyle { none, velodyne_time, ouster_t, livox_offset_time, hesai_timestamp };

namespace detail {

inline PointField time_point_field(PointTimeStyle style, std::uint32_t offset) {
  switch (style) {
    case PointTimeStyle::velodyne_time:
      return {"time", offset, io::ScalarType::float32, 1};
    case PointTimeStyle::ouster_t:
      return {"t", offset, io::ScalarType::uint32, 1};
    case PointTimeStyle::livox_offset_time:
      return {"offset_time", offset, io::ScalarType::uint32, 1};
    case PointTimeStyle::hesai_timestamp:
    case PointTimeStyle::none:
      break;
  }
  return {"timestamp", offset, io::ScalarType::float64, 1};
}

/// Stores relative time `t` (seconds after the stamp) as the style's field does; the unsigned
/// fields clamp negative times at 0.
inline void store_time(unsigned char* p, PointTimeStyle style, double t, std::int64_t stamp_ns,
                       io::Endian order) {
  switch (style) {
    case PointTimeStyle::velodyne_time:
      return io::store<float>(p, static_cast<float>(t), order);
    case PointTimeStyle::ouster_t:
    case PointTimeStyle::livox_offset_time:
      return io::store<std::uint32_t>(
          p, static_cast<std::uint32_t>(std::lround(std::max(0.0, t) * 1e9)), order);
    case PointTimeStyle::hesai_timestamp:
      return io::store<double>(p, static_cast<double>(stamp_ns) * 1e-9 + t, order);
    case PointTimeStyle::none:
      return;
  }
}

}  // namespace detail

/// A PointCloud2 message (1 x N) holding `cloud`, its times (relative to `stamp_ns`) written in
/// `style` (none when the cloud has no times).
inline std::vector<unsigned char> encode_pointcloud2(
    const io::DecodedCloud& cloud, std::int64_t stamp_ns, const std::string& frame_id,
    Serialization serialization, PointTimeStyle style, io::Endian data_order = io::Endian::little) {
  PointCloud2View c;
  c.header = {stamp_ns, frame_id};
  c.height = 1;
  c.width = static_cast<std::uint32_t>(cloud.size());
  c.fields = {{"x", 0, io::ScalarType::float32, 1},
              {"y", 4, io::ScalarType::float32, 1},
              {"z", 8, io::ScalarType::float32, 1}};
  std::uint32_t step = 12;
  if (cloud.has_intensities()) c.fields.push_back({"intensity", step, io::ScalarType::float32, 1});
  if (cloud.has_intensities()) step += 4;
  if (!cloud.has_times()) style = PointTimeStyle::none;
  if (style != PointTimeStyle::none) {
    step = style == PointTimeStyle::hesai_timestamp ? (step + 7) / 8 * 8 : step;
    c.fields.push_back(detail::time_point_field(style, step));
    step += style == PointTimeStyle::hesai_timestamp ? 8 : 4;
  }
  c.point_step = step;
  c.row_step = step * c.width;
  c.order = data_order;
  std::vector<unsigned char> data(std::size_t{c.row_step}, 0);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    unsigned char* p = data.data() + i * step;
    for (int a = 0; a < 3; ++a)
      io::store<float>(p + 4 * a, static_cast<float>(cloud.points[i][a]), data_order);
    if (cloud.has_intensities())
      io::store<float>(p + 12, static_cast<float>(cloud.intensities[i]), data_order);
    if (style != PointTimeStyle::none)
      detail::store_time(p + c.fields.back().offset, style, cloud.times[i], stamp_ns, data_order);
  }
  c.data = data.data();
  c.data_size = data.size();
  c.is_dense = true;
  return write_pointcloud2(c, serialization);
}

/// A Livox CustomMsg holding `cloud` (timebase = the stamp; times clamped at 0).
inline LivoxCustomMsg livox_message(const io::DecodedCloud& cloud, std::int64_t stamp_ns,
                                    const std::string& frame_id) {
  LivoxCustomMsg m;
  m.header = {stamp_ns, frame_id};
  m.timebase = static_cast<std::uint64_t>(stamp_ns);
  m.points.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    LivoxPoint& p = m.points[i];
    p.x = static_cast<float>(cloud.points[i].x());
    p.y = static_cast<float>(cloud.points[i].y());
    p.z = static_cast<float>(cloud.points[i].z());
    if (cloud.has_intensities())
      p.reflectivity = static_cast<std::uint8_t>(std::clamp(cloud.intensities[i], 0.0, 255.0));
    if (cloud.has_times())
      p.offset_time = static_cast<std::uint32_t>(std::lround(std::max(0.0, cloud.times[i]) * 1e9));
  }
  return m;
}

}  // namespace ulc::bags
