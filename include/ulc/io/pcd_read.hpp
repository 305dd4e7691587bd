// PCD v0.7 reader: DATA ascii, binary and binary_compressed, any FIELDS layout.
//
// Fields: see field_roles.hpp (x y z required; intensity; time from t / time / timestamp /
// offset_time, integer times are nanoseconds). Points with a NaN / Inf coordinate are dropped and
// counted (organised clouds, HEIGHT > 1, mark missing returns that way), so the result is
// always a flat list of finite points.
//
// binary:            POINTS records of point_size bytes, little endian, fields in FIELDS order.
// binary_compressed: uint32 compressed size, uint32 uncompressed size, then LZF data that
//                    decodes to the fields one after another (all x, then all y, ...; each field
//                    COUNT * SIZE * POINTS bytes).
// ascii:             one point per line, sum(COUNT) numbers; blank lines are ignored.
//
// Hostile files: every size in the header is checked against the bytes actually present before
// anything is allocated, so no read allocates more than the file size justifies.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "ulc/io/byte_reader.hpp"
#include "ulc/io/decoded_cloud.hpp"
#include "ulc/io/field_roles.hpp"
#include "ulc/io/file_bytes.hpp"
#include "ulc/io/lzf.hpp"
#include "ulc/io/pcd_header.hpp"
#include "ulc/io/read_stats.hpp"
#include "ulc/io/text_parse.hpp"

namespace ulc::io {

namespace detail {

/// Reads the role fields of records laid out as base + i * stride + field offset.
inline DecodedCloud pcd_decode_records(const unsigned char* base, std::size_t n, std::size_t stride,
                                       const std::vector<std::size_t>& offsets, const PcdHeader& h,
                                       const FieldRoles& r, ReadStats& stats) {
  DecodedBuilder out(n, r.has_intensity(), r.has_time());
  auto value = [&](const unsigned char* rec, std::size_t f) {
    return decode_scalar(rec + offsets[f], h.fields[f].type, Endian::little);
  };
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char* rec = base + i * stride;
    out.add(value(rec, r.x), value(rec, r.y), value(rec, r.z),
            r.has_intensity() ? value(rec, r.intensity) : 0.0,
            r.has_time() ? value(rec, r.time) * r.time_scale : 0.0);
  }
  return out.finish(stats);
}

inline DecodedCloud pcd_read_binary(ByteReader& in, const PcdHeader& h, const FieldRoles& r,
                                    ReadStats& stats) {
  if (h.points > in.remaining() / h.point_size)
    in.fail("truncated binary data: header claims " + std::to_string(h.points) + " points of " +
            std::to_string(h.point_size) + " bytes but only " + std::to_string(in.remaining()) +
            " bytes follow the header");
  const unsigned char* base = in.take(h.points * h.point_size, "binary data");
  return pcd_decode_records(base, h.points, h.point_size, h.offsets, h, r, stats);
}

inline DecodedCloud pcd_read_compressed(ByteReader& in, const PcdHeader& h, const FieldRoles& r,
                                        ReadStats& stats) {
  if (h.points == 0 && in.remaining() < 8) return DecodedBuilder(0, false, false).finish(stats);
  const std::size_t sizes_at = in.offset();
  const std::size_t compressed = in.read<std::uint32_t>(Endian::little, "compressed size field");
  const std::size_t uncompressed =
      in.read<std::uint32_t>(Endian::little, "uncompressed size field");
  if (h.points > UINT32_MAX / h.point_size || uncompressed != h.points * h.point_size)
    in.fail_at(sizes_at + 4, "uncompressed size " + std::to_string(uncompressed) +
                                 " does not match POINTS * point size = " +
                                 std::to_string(h.points) + " * " + std::to_string(h.point_size));
  if (compressed > in.remaining())
    in.fail("truncated compressed data: header says " + std::to_string(compressed) +
            " bytes, only " + std::to_string(in.remaining()) + " follow");
  if (uncompressed > compressed * kLzfMaxExpansion)
    in.fail_at(sizes_at, "uncompressed size " + std::to_string(uncompressed) +
                             " is impossible for " + std::to_string(compressed) +
                             " bytes of LZF data");
  const std::size_t lzf_at = in.offset();
  const unsigned char* lzf = in.take(compressed, "compressed data");
  std::vector<unsigned char> raw(uncompressed);
  const LzfResult res = lzf_decompress(lzf, compressed, raw.data(), raw.size());
  if (!res.ok()) in.fail_at(lzf_at + res.input_offset, res.message());
  if (res.output_size != uncompressed)
    in.fail_at(lzf_at, "LZF data decodes to " + std::to_string(res.output_size) +
                           " bytes, header says " + std::to_string(uncompressed));
  // Field-major: field f starts at POINTS * (its offset in a record); element stride is its size.
  const std::size_t n = h.points;
  DecodedBuilder out(n, r.has_intensity(), r.has_time());
  auto column = [&](std::size_t f) { return raw.data() + n * h.offsets[f]; };
  auto value = [&](std::size_t f, std::size_t i) {
    const std::size_t stride = size_of(h.fields[f].type) * h.fields[f].count;
    return decode_scalar(column(f) + i * stride, h.fields[f].type, Endian::little);
  };
  for (std::size_t i = 0; i < n; ++i)
    out.add(value(r.x, i), value(r.y, i), value(r.z, i),
            r.has_intensity() ? value(r.intensity, i) : 0.0,
            r.has_time() ? value(r.time, i) * r.time_scale : 0.0);
  return out.finish(stats);
}

inline DecodedCloud pcd_read_ascii(ByteReader& in, const PcdHeader& h, const FieldRoles& r,
                                   ReadStats& stats) {
  // Each number needs at least one character and one separator (the last line may lack "\n").
  const std::size_t min_bytes_per_point = 2 * h.value_count;
  if (h.points > (in.remaining() + 1) / min_bytes_per_point)
    in.fail("truncated ascii data: header claims " + std::to_string(h.points) +
            " points but only " + std::to_string(in.remaining()) + " bytes follow the header");
  // Index of the first number of each field on a line.
  std::vector<std::size_t> first(h.fields.size());
  std::vector<ScalarType> token_type;
  for (std::size_t f = 0; f < h.fields.size(); ++f) {
    first[f] = token_type.size();
    token_type.insert(token_type.end(), h.fields[f].count, h.fields[f].type);
  }
  DecodedBuilder out(h.points, r.has_intensity(), r.has_time());
  std::vector<std::string_view> tok;
  std::vector<double> values(h.value_count);
  std::size_t line_no = h.data_line;
  std::size_t got = 0;
  std::string_view line;
  auto fail_line = [&](const std::string& reason) {
    throw IoError(in.file(), at_line(line_no), reason);
  };
  while (in.read_line(line)) {
    ++line_no;
    split_tokens(line, tok);
    if (tok.empty()) continue;
    if (got == h.points) fail_line("more data lines than POINTS " + std::to_string(h.points));
    if (tok.size() != h.value_count)
      fail_line("expected " + std::to_string(h.value_count) + " numbers, found " +
                std::to_string(tok.size()));
    for (std::size_t k = 0; k < tok.size(); ++k)
      if (!parse_value(tok[k], token_type[k], values[k]))
        fail_line(quote_token(tok[k]) + " is not a number");
    out.add(values[first[r.x]], values[first[r.y]], values[first[r.z]],
            r.has_intensity() ? values[first[r.intensity]] : 0.0,
            r.has_time() ? values[first[r.time]] * r.time_scale : 0.0);
    ++got;
  }
  if (got != h.points)
    fail_line("truncated ascii data: found " + std::to_string(got) + " of " +
              std::to_string(h.points) + " points");
  return out.finish(stats);
}

}  // namespace detail

/// Parses a PCD file already in memory; `file` names it in errors.
inline DecodedCloud decode_pcd(const unsigned char* data, std::size_t size, const std::string& file,
                               ReadStats* stats = nullptr) {
  ReadStats local;
  ReadStats& st = stats ? *stats : local;
  st = ReadStats{};
  ByteReader in(data, size, file);
  const PcdHeader h = parse_pcd_header(in);
  const FieldRoles roles = assign_field_roles(h.fields, file, at_line(h.data_line));
  st.format = "pcd";
  st.encoding = to_string(h.encoding);
  describe_fields(h.fields, roles, st);
  st.width = h.width;
  st.height = h.height;
  st.points_in_file = h.points;
  switch (h.encoding) {
    case PcdEncoding::ascii:
      return detail::pcd_read_ascii(in, h, roles, st);
    case PcdEncoding::binary:
      return detail::pcd_read_binary(in, h, roles, st);
    case PcdEncoding::binary_compressed:
      return detail::pcd_read_compressed(in, h, roles, st);
  }
  return {};
}

inline DecodedCloud decode_pcd(const std::vector<unsigned char>& bytes, const std::string& file,
                               ReadStats* stats = nullptr) {
  return decode_pcd(bytes.data(), bytes.size(), file, stats);
}

inline DecodedCloud read_pcd_decoded(const std::filesystem::path& path,
                                     ReadStats* stats = nullptr) {
  return decode_pcd(read_file_bytes(path), path.string(), stats);
}

/// Reads a PCD file into any writable cloud type (see ulc/core/point_traits.hpp).
template <typename Cloud>
Cloud read_pcd(const std::filesystem::path& path, ReadStats* stats = nullptr) {
  return to_cloud<Cloud>(read_pcd_decoded(path, stats));
}

}  // namespace ulc::io
