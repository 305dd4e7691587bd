// PLY reader: ascii, binary_little_endian and binary_big_endian (format 1.0).
//
// Points come from the `vertex` element; its properties follow field_roles.hpp (x y z required,
// intensity, time from t / time / timestamp / offset_time). Elements before `vertex` are parsed
// record by record to skip them (list properties included); elements after it are never read.
// In ascii files each record is one line (as every PLY writer does), which lets errors name the
// line. Non-finite points are dropped and counted, as for PCD.
#pragma once

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "ulc/io/byte_reader.hpp"
#include "ulc/io/decoded_cloud.hpp"
#include "ulc/io/field_roles.hpp"
#include "ulc/io/file_bytes.hpp"
#include "ulc/io/ply_header.hpp"
#include "ulc/io/read_stats.hpp"
#include "ulc/io/text_parse.hpp"

namespace ulc::io {

namespace detail {

/// Reads one binary record of `e`; scalar values land in `values` (lists are skipped: NaN).
inline void ply_binary_record(ByteReader& in, const PlyElement& e, Endian order,
                              std::vector<double>* values) {
  for (std::size_t k = 0; k < e.properties.size(); ++k) {
    const PlyProperty& p = e.properties[k];
    if (!p.is_list) {
      const double v = decode_scalar(in.take(size_of(p.type), "vertex data"), p.type, order);
      if (values) (*values)[k] = v;
      continue;
    }
    const std::size_t at = in.offset();
    const double count =
        decode_scalar(in.take(size_of(p.count_type), "list count"), p.count_type, order);
    if (count < 0) in.fail_at(at, "negative count in list property " + p.name);
    const std::size_t item = size_of(p.type);
    if (count > static_cast<double>(in.remaining() / item))
      in.fail_at(at, "truncated list property " + p.name + " of element " + e.name + ": " +
                         std::to_string(static_cast<std::uint64_t>(count)) + " items do not fit");
    in.skip(static_cast<std::size_t>(count) * item, "list items");
    if (values) (*values)[k] = std::numeric_limits<double>::quiet_NaN();
  }
}

/// Parses one ascii record of `e` from its tokens; throws via `fail` on a bad token or count.
template <typename Fail>
void ply_ascii_record(const std::vector<std::string_view>& tok, const PlyElement& e,
                      std::vector<double>& values, const Fail& fail) {
  std::size_t t = 0;
  auto next = [&](ScalarType type) {
    if (t >= tok.size())
      fail("too few values for element " + e.name + " (found " + std::to_string(tok.size()) + ")");
    double v = 0;
    if (!parse_value(tok[t], type, v)) fail(quote_token(tok[t]) + " is not a number");
    ++t;
    return v;
  };
  for (std::size_t k = 0; k < e.properties.size(); ++k) {
    const PlyProperty& p = e.properties[k];
    if (!p.is_list) {
      values[k] = next(p.type);
      continue;
    }
    std::uint64_t count = 0;
    if (t >= tok.size() || !parse_uint(tok[t], count))
      fail("list property " + p.name + " needs a non-negative integer count");
    ++t;
    if (count > tok.size() - t)
      fail("list property " + p.name + " claims " + std::to_string(count) + " items, only " +
           std::to_string(tok.size() - t) + " values follow");
    for (std::uint64_t c = 0; c < count; ++c) next(p.type);
    values[k] = std::numeric_limits<double>::quiet_NaN();
  }
  if (t != tok.size())
    fail("expected " + std::to_string(t) + " values for element " + e.name + ", found " +
         std::to_string(tok.size()));
}

inline DecodedCloud ply_read_binary(ByteReader& in, const PlyHeader& h, std::size_t vertex,
                                    const FieldRoles& r, ReadStats& stats) {
  const Endian order = h.format == PlyFormat::binary_big_endian ? Endian::big : Endian::little;
  for (std::size_t k = 0; k < vertex; ++k) {
    const PlyElement& e = h.elements[k];
    if (e.properties.empty()) continue;  // zero-size records: nothing to skip
    for (std::size_t i = 0; i < e.count; ++i) ply_binary_record(in, e, order, nullptr);
  }
  const PlyElement& v = h.elements[vertex];
  if (v.count > in.remaining() / v.min_binary_record())
    in.fail("truncated vertex data: header claims " + std::to_string(v.count) +
            " vertices of at least " + std::to_string(v.min_binary_record()) + " bytes but only " +
            std::to_string(in.remaining()) + " bytes follow");
  DecodedBuilder out(v.count, r.has_intensity(), r.has_time());
  std::vector<double> values(v.properties.size());
  for (std::size_t i = 0; i < v.count; ++i) {
    ply_binary_record(in, v, order, &values);
    out.add(values[r.x], values[r.y], values[r.z], r.has_intensity() ? values[r.intensity] : 0.0,
            r.has_time() ? values[r.time] * r.time_scale : 0.0);
  }
  return out.finish(stats);
}

inline DecodedCloud ply_read_ascii(ByteReader& in, const PlyHeader& h, std::size_t vertex,
                                   const FieldRoles& r, ReadStats& stats) {
  std::size_t line_no = h.end_line;
  auto fail = [&](const std::string& reason) {
    throw IoError(in.file(), at_line(line_no), reason);
  };
  std::vector<std::string_view> tok;
  std::string_view line;
  auto next_record = [&](const PlyElement& e) {
    while (in.read_line(line)) {
      ++line_no;
      split_tokens(line, tok);
      if (!tok.empty()) return;
    }
    ++line_no;
    fail("truncated ascii data: element " + e.name + " needs " + std::to_string(e.count) +
         " records");
  };
  std::vector<double> values;
  for (std::size_t k = 0; k < vertex; ++k) {
    const PlyElement& e = h.elements[k];
    if (e.properties.empty()) continue;
    values.resize(e.properties.size());
    for (std::size_t i = 0; i < e.count; ++i) {
      next_record(e);
      ply_ascii_record(tok, e, values, fail);
    }
  }
  const PlyElement& v = h.elements[vertex];
  // Each value needs a character and a separator (the last line may lack "\n").
  const std::size_t min_bytes = 2 * v.properties.size();
  if (v.count > (in.remaining() + 1) / min_bytes)
    fail("truncated ascii data: header claims " + std::to_string(v.count) + " vertices but only " +
         std::to_string(in.remaining()) + " bytes follow");
  DecodedBuilder out(v.count, r.has_intensity(), r.has_time());
  values.resize(v.properties.size());
  for (std::size_t i = 0; i < v.count; ++i) {
    next_record(v);
    ply_ascii_record(tok, v, values, fail);
    out.add(values[r.x], values[r.y], values[r.z], r.has_intensity() ? values[r.intensity] : 0.0,
            r.has_time() ? values[r.time] * r.time_scale : 0.0);
  }
  return out.finish(stats);
}

}  // namespace detail

/// Parses a PLY file already in memory; `file` names it in errors.
inline DecodedCloud decode_ply(const unsigned char* data, std::size_t size, const std::string& file,
                               ReadStats* stats = nullptr) {
  ReadStats local;
  ReadStats& st = stats ? *stats : local;
  st = ReadStats{};
  ByteReader in(data, size, file);
  const PlyHeader h = parse_ply_header(in);
  std::size_t vertex = h.elements.size();
  for (std::size_t k = 0; k < h.elements.size() && vertex == h.elements.size(); ++k)
    if (h.elements[k].name == "vertex") vertex = k;
  if (vertex == h.elements.size()) throw IoError(file, at_line(h.end_line), "no vertex element");
  const PlyElement& v = h.elements[vertex];
  std::vector<FieldDesc> fields;
  for (const PlyProperty& p : v.properties) fields.push_back({p.name, p.type, p.is_list ? 0u : 1u});
  const FieldRoles roles = assign_field_roles(fields, file, at_line(v.line));
  st.format = "ply";
  st.encoding = to_string(h.format);
  describe_fields(fields, roles, st);
  st.width = v.count;
  st.height = 1;
  st.points_in_file = v.count;
  if (h.format == PlyFormat::ascii) return detail::ply_read_ascii(in, h, vertex, roles, st);
  return detail::ply_read_binary(in, h, vertex, roles, st);
}

inline DecodedCloud decode_ply(const std::vector<unsigned char>& bytes, const std::string& file,
                               ReadStats* stats = nullptr) {
  return decode_ply(bytes.data(), bytes.size(), file, stats);
}

inline DecodedCloud read_ply_decoded(const std::filesystem::path& path,
                                     ReadStats* stats = nullptr) {
  return decode_ply(read_file_bytes(path), path.string(), stats);
}

/// Reads a PLY file into any writable cloud type (see ulc/core/point_traits.hpp).
template <typename Cloud>
Cloud read_ply(const std::filesystem::path& path, ReadStats* stats = nullptr) {
  return to_cloud<Cloud>(read_ply_decoded(path, stats));
}

}  // namespace ulc::io
