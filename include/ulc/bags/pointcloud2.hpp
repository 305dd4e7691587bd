// sensor_msgs/PointCloud2, any field layout:
//   Header header; uint32 height; uint32 width; PointField[] fields; bool is_bigendian;
//   uint32 point_step; uint32 row_step; uint8[] data; bool is_dense
//   PointField: string name; uint32 offset; uint8 datatype (1 INT8 .. 8 FLOAT64); uint32 count
// parse_pointcloud2 reads the message and checks that the layout fits its data (every field
// inside point_step, every row inside row_step, every row inside data); the points stay in the
// message's bytes, read by PointCloud2Layout::value.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ulc/bags/ros_header.hpp"
#include "ulc/bags/serialization.hpp"
#include "ulc/io/scalar_type.hpp"

namespace ulc::bags {

struct PointField {
  std::string name;
  std::uint32_t offset = 0;
  io::ScalarType type = io::ScalarType::float32;
  std::uint32_t count = 1;
};

struct PointCloud2View {
  RosHeader header;
  std::uint32_t height = 0, width = 0;
  std::vector<PointField> fields;
  io::Endian order = io::Endian::little;
  std::uint32_t point_step = 0, row_step = 0;
  const unsigned char* data = nullptr;  ///< into the message: valid as long as it is
  std::size_t data_size = 0;
  bool is_dense = false;

  std::size_t point_count() const { return std::size_t{height} * width; }
  /// Byte address of point i (row-major over height x width).
  const unsigned char* point(std::size_t i) const {
    return data + (i / width) * std::size_t{row_step} + (i % width) * std::size_t{point_step};
  }
  const PointField* field(const std::string& name) const {
    for (const PointField& f : fields)
      if (f.name == name) return &f;
    return nullptr;
  }
};

/// PointField.datatype -> ScalarType (1 INT8, 2 UINT8, 3 INT16, 4 UINT16, 5 INT32, 6 UINT32,
/// 7 FLOAT32, 8 FLOAT64); nullopt for anything else.
inline std::optional<io::ScalarType> point_field_type(std::uint8_t datatype) {
  using T = io::ScalarType;
  static constexpr T kTypes[] = {T::int8,  T::uint8,  T::int16,   T::uint16,
                                 T::int32, T::uint32, T::float32, T::float64};
  if (datatype < 1 || datatype > 8) return std::nullopt;
  return kTypes[datatype - 1];
}

inline std::uint8_t point_field_datatype(io::ScalarType t) {
  using T = io::ScalarType;
  switch (t) {
    case T::int8:
      return 1;
    case T::uint8:
      return 2;
    case T::int16:
      return 3;
    case T::uint16:
      return 4;
    case T::int32:
      return 5;
    case T::uint32:
      return 6;
    case T::float32:
      return 7;
    case T::float64:
      return 8;
    case T::int64:
    case T::uint64:
      break;  // PointCloud2 has no 64-bit integers
  }
  return 0;
}

namespace detail {

inline PointField read_point_field(MessageReader& in) {
  PointField f;
  f.name = std::string(in.read_string("fields.name"));
  f.offset = in.read<std::uint32_t>("fields.offset");
  const std::uint8_t datatype = in.read<std::uint8_t>("fields.datatype");
  const auto type = point_field_type(datatype);
  if (!type)
    in.fail("field '" + f.name + "' has datatype " + std::to_string(datatype) +
            " (PointField defines 1 to 8)");
  f.type = *type;
  f.count = in.read<std::uint32_t>("fields.count");
  return f;
}

/// Every field's bytes inside point_step, every row inside row_step, the rows inside data.
inline void check_layout(const PointCloud2View& c, MessageReader& in) {
  for (const PointField& f : c.fields) {
    const std::uint64_t end =
        std::uint64_t{f.offset} + std::uint64_t{f.count} * io::size_of(f.type);
    if (end > c.point_step)
      in.fail("field '" + f.name + "' ends at byte " + std::to_string(end) +
              " of a point, past point_step " + std::to_string(c.point_step));
  }
  if (std::uint64_t{c.width} * c.point_step > c.row_step)
    in.fail("row_step " + std::to_string(c.row_step) + " is smaller than width " +
            std::to_string(c.width) + " x point_step " + std::to_string(c.point_step));
  if (std::uint64_t{c.height} * c.row_step > c.data_size)
    in.fail("height " + std::to_string(c.height) + " x row_step " + std::to_string(c.row_step) +
            " is more than the " + std::to_string(c.data_size) + " bytes of data");
}

}  // namespace detail

inline PointCloud2View parse_pointcloud2(MessageReader& in, Serialization serialization) {
  PointCloud2View c;
  c.header = read_header(in, serialization);
  c.height = in.read<std::uint32_t>("height");
  c.width = in.read<std::uint32_t>("width");
  const std::uint32_t n_fields = in.read_count(13, "fields");  // name length + 9 bytes at least
  c.fields.reserve(n_fields);
  for (std::uint32_t i = 0; i < n_fields; ++i) c.fields.push_back(detail::read_point_field(in));
  c.order = in.read_bool("is_bigendian") ? io::Endian::big : io::Endian::little;
  c.point_step = in.read<std::uint32_t>("point_step");
  c.row_step = in.read<std::uint32_t>("row_step");
  const std::uint32_t n_data = in.read_count(1, "data");
  c.data = in.take(n_data, "data");
  c.data_size = n_data;
  c.is_dense = in.read_bool("is_dense");
  detail::check_layout(c, in);
  return c;
}

/// One message from a layout (our writers: tests, benchmarks). `data` holds height x row_step.
inline std::vector<unsigned char> write_pointcloud2(const PointCloud2View& c,
                                                    Serialization serialization,
                                                    io::Endian cdr_order = io::Endian::little) {
  MessageWriter out(serialization, cdr_order);
  write_header(out, serialization, c.header);
  out.write<std::uint32_t>(c.height);
  out.write<std::uint32_t>(c.width);
  out.write_count(c.fields.size());
  for (const PointField& f : c.fields) {
    out.write_string(f.name);
    out.write<std::uint32_t>(f.offset);
    out.write<std::uint8_t>(point_field_datatype(f.type));
    out.write<std::uint32_t>(f.count);
  }
  out.write_bool(c.order == io::Endian::big);
  out.write<std::uint32_t>(c.point_step);
  out.write<std::uint32_t>(c.row_step);
  out.write_count(c.data_size);
  out.write_bytes(c.data, c.data_size);
  out.write_bool(c.is_dense);
  return out.release();
}

}  // namespace ulc::bags
