// PCD v0.7 header parsing (the text lines before the data).
//
// Accepted lines, each at most once: VERSION (any value), FIELDS (or the old COLUMNS), SIZE,
// TYPE, COUNT (default all 1), WIDTH, HEIGHT (default 1), VIEWPOINT (ignored), POINTS (default
// WIDTH * HEIGHT; must equal it), and DATA ascii | binary | binary_compressed, which ends the
// header. '#' lines and blank lines are comments. Anything else is an error, as is a TYPE/SIZE
// pair PCD does not define (F2, I3, ...). Errors name the header line.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ulc/io/byte_reader.hpp"
#include "ulc/io/field_roles.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/scalar_type.hpp"
#include "ulc/io/text_parse.hpp"

namespace ulc::io {

enum class PcdEncoding { ascii, binary, binary_compressed };

inline const char* to_string(PcdEncoding e) {
  switch (e) {
    case PcdEncoding::ascii:
      return "ascii";
    case PcdEncoding::binary:
      return "binary";
    case PcdEncoding::binary_compressed:
      return "binary_compressed";
  }
  return "?";
}

struct PcdHeader {
  std::vector<FieldDesc> fields;
  std::vector<std::size_t> offsets;  ///< byte offset of each field inside one point record
  std::size_t point_size = 0;        ///< bytes per point: sum of SIZE * COUNT
  std::size_t value_count = 0;       ///< numbers per point: sum of COUNT (ascii tokens per line)
  std::size_t width = 0, height = 1, points = 0;
  PcdEncoding encoding = PcdEncoding::binary;
  std::size_t data_offset = 0;  ///< first byte after the DATA line
  std::size_t points_line = 0;  ///< line number of POINTS (or WIDTH), for data-size errors
  std::size_t data_line = 0;    ///< line number of DATA
};

namespace detail {

/// A COUNT this large is never a real descriptor; the cap keeps size arithmetic far from overflow.
constexpr std::uint64_t kPcdMaxCount = std::uint64_t{1} << 24;

struct PcdHeaderLines {
  const std::string& file;
  std::size_t line = 0;

  [[noreturn]] void fail(const std::string& reason) const {
    throw IoError(file, at_line(line), reason);
  }
  std::uint64_t uint_value(std::string_view key, std::string_view token) const {
    std::uint64_t v = 0;
    if (!parse_uint(token, v))
      fail(std::string(key) + " value " + quote_token(token) + " is not a non-negative integer");
    return v;
  }
};

}  // namespace detail

/// Parses the header from the start of `reader` and leaves it at the first data byte.
inline PcdHeader parse_pcd_header(ByteReader& reader) {
  const std::string& file = reader.file();
  if (reader.size() == 0) throw IoError(file, "", "empty file");
  detail::PcdHeaderLines ctx{file};
  PcdHeader h;
  std::vector<std::string_view> names, sizes, types, counts;
  bool seen_version = false, seen_fields = false, seen_size = false, seen_type = false,
       seen_count = false, seen_width = false, seen_height = false, seen_viewpoint = false,
       seen_points = false, seen_data = false;
  std::uint64_t width = 0, height = 1, points = 0;
  std::size_t width_line = 0, fields_line = 0, size_line = 0, type_line = 0, count_line = 0;
  std::string_view line;
  std::vector<std::string_view> tok;
  while (!seen_data && reader.read_line(line)) {
    ++ctx.line;
    split_tokens(line, tok);
    if (tok.empty() || tok[0].front() == '#') continue;
    const std::string_view key = tok[0];
    auto once = [&](bool& seen) {
      if (seen) ctx.fail("duplicate " + std::string(key) + " line");
      seen = true;
    };
    auto single = [&]() {
      if (tok.size() != 2) ctx.fail(std::string(key) + " needs exactly one value");
      return ctx.uint_value(key, tok[1]);
    };
    auto rest = [&]() { return std::vector<std::string_view>(tok.begin() + 1, tok.end()); };
    if (key == "VERSION") {
      once(seen_version);
    } else if (key == "FIELDS" || key == "COLUMNS") {
      once(seen_fields);
      fields_line = ctx.line;
      names = rest();
      if (names.empty()) ctx.fail("FIELDS lists no fields");
    } else if (key == "SIZE") {
      once(seen_size);
      size_line = ctx.line;
      sizes = rest();
    } else if (key == "TYPE") {
      once(seen_type);
      type_line = ctx.line;
      types = rest();
    } else if (key == "COUNT") {
      once(seen_count);
      count_line = ctx.line;
      counts = rest();
    } else if (key == "WIDTH") {
      once(seen_width);
      width = single();
      width_line = ctx.line;
    } else if (key == "HEIGHT") {
      once(seen_height);
      height = single();
    } else if (key == "VIEWPOINT") {
      once(seen_viewpoint);
    } else if (key == "POINTS") {
      once(seen_points);
      points = single();
      h.points_line = ctx.line;
    } else if (key == "DATA") {
      once(seen_data);
      if (tok.size() != 2) ctx.fail("DATA needs exactly one value");
      if (tok[1] == "ascii")
        h.encoding = PcdEncoding::ascii;
      else if (tok[1] == "binary")
        h.encoding = PcdEncoding::binary;
      else if (tok[1] == "binary_compressed")
        h.encoding = PcdEncoding::binary_compressed;
      else
        ctx.fail("unknown DATA kind " + quote_token(tok[1]) +
                 " (expected ascii, binary or binary_compressed)");
      h.data_line = ctx.line;
    } else {
      ctx.fail("unknown header line starting with " + quote_token(key));
    }
  }
  ++ctx.line;  // errors about the header as a whole point just past it
  if (!seen_data) ctx.fail("missing DATA line (not a PCD file?)");
  ctx.line = h.data_line;
  if (!seen_fields) ctx.fail("missing FIELDS line");
  if (!seen_size) ctx.fail("missing SIZE line");
  if (!seen_type) ctx.fail("missing TYPE line");
  if (!seen_width) ctx.fail("missing WIDTH line");
  const std::size_t n = names.size();
  ctx.line = fields_line;
  if (sizes.size() != n || types.size() != n || (seen_count && counts.size() != n))
    ctx.fail("FIELDS has " + std::to_string(n) + " entries but SIZE has " +
             std::to_string(sizes.size()) + ", TYPE " + std::to_string(types.size()) +
             (seen_count ? ", COUNT " + std::to_string(counts.size()) : std::string()));

  for (std::size_t i = 0; i < n; ++i) {
    FieldDesc f;
    f.name = std::string(names[i]);
    ctx.line = size_line;
    const std::uint64_t size = ctx.uint_value("SIZE", sizes[i]);
    ctx.line = type_line;
    if (types[i].size() != 1)
      ctx.fail("TYPE " + quote_token(types[i]) + " of field " + f.name + " is not I, U or F");
    const auto type = pcd_scalar_type(types[i][0], size);
    if (!type)
      ctx.fail("field " + f.name + " has TYPE " + std::string(types[i]) + " with SIZE " +
               std::to_string(size) + ", which PCD does not define");
    f.type = *type;
    ctx.line = count_line;
    const std::uint64_t count = seen_count ? ctx.uint_value("COUNT", counts[i]) : 1;
    if (count < 1 || count > detail::kPcdMaxCount)
      ctx.fail("field " + f.name + " has COUNT " + std::to_string(count) + ", expected 1 to " +
               std::to_string(detail::kPcdMaxCount));
    f.count = static_cast<std::size_t>(count);
    h.offsets.push_back(h.point_size);
    h.point_size += size_of(f.type) * f.count;
    h.value_count += f.count;
    h.fields.push_back(std::move(f));
  }

  ctx.line = h.data_line;
  if (height == 0 && width != 0) ctx.fail("HEIGHT is 0 but WIDTH is not");
  if (height != 0 && width > UINT64_MAX / height) ctx.fail("WIDTH * HEIGHT overflows");
  if (!seen_points) {
    points = width * height;
    h.points_line = width_line;
  } else if (points != width * height) {
    ctx.line = h.points_line;
    ctx.fail("POINTS " + std::to_string(points) + " does not match WIDTH * HEIGHT = " +
             std::to_string(width) + " * " + std::to_string(height));
  }
  h.width = static_cast<std::size_t>(width);
  h.height = static_cast<std::size_t>(height);
  h.points = static_cast<std::size_t>(points);
  h.data_offset = reader.offset();
  return h;
}

}  // namespace ulc::io
