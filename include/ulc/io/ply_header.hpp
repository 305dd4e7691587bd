// PLY header parsing: "ply", "format <ascii|binary_little_endian|binary_big_endian> 1.0",
// "comment ..." / "obj_info ...", "element <name> <count>", "property <type> <name>",
// "property list <count type> <item type> <name>", "end_header". Type names: char uchar short
// ushort int uint float double and int8 uint8 int16 uint16 int32 uint32 float32 float64.
// Anything else is an error naming the header line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ulc/io/byte_reader.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/scalar_type.hpp"
#include "ulc/io/text_parse.hpp"

namespace ulc::io {

enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

inline const char* to_string(PlyFormat f) {
  switch (f) {
    case PlyFormat::ascii:
      return "ascii";
    case PlyFormat::binary_little_endian:
      return "binary_little_endian";
    case PlyFormat::binary_big_endian:
      return "binary_big_endian";
  }
  return "?";
}

struct PlyProperty {
  std::string name;
  ScalarType type = ScalarType::float32;  ///< value type (item type for a list)
  bool is_list = false;
  ScalarType count_type = ScalarType::uint8;  ///< lists only; always an integer type
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
  std::size_t line = 0;  ///< header line of the "element" keyword

  bool has_lists() const {
    for (const PlyProperty& p : properties)
      if (p.is_list) return true;
    return false;
  }
  /// Bytes of the smallest possible binary record (lists empty).
  std::size_t min_binary_record() const {
    std::size_t bytes = 0;
    for (const PlyProperty& p : properties) bytes += size_of(p.is_list ? p.count_type : p.type);
    return bytes;
  }
};

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;  ///< first byte after "end_header\n"
  std::size_t end_line = 0;     ///< line number of end_header
};

/// Parses the header from the start of `reader` and leaves it at the first data byte.
inline PlyHeader parse_ply_header(ByteReader& reader) {
  const std::string& file = reader.file();
  if (reader.size() == 0) throw IoError(file, "", "empty file");
  std::size_t line_no = 0;
  auto fail = [&](const std::string& reason) { throw IoError(file, at_line(line_no), reason); };
  std::string_view line;
  std::vector<std::string_view> tok;
  reader.read_line(line);
  line_no = 1;
  if (split_tokens(line) != std::vector<std::string_view>{"ply"})
    fail("not a PLY file (the first line is not 'ply')");

  PlyHeader h;
  bool seen_format = false, seen_end = false;
  auto type_of = [&](std::string_view name) {
    const auto t = ply_scalar_type(name);
    if (!t) fail("unknown property type " + quote_token(name));
    return *t;
  };
  while (!seen_end && reader.read_line(line)) {
    ++line_no;
    split_tokens(line, tok);
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (seen_format) fail("duplicate format line");
      seen_format = true;
      if (tok.size() != 3) fail("format line needs a format and a version");
      if (tok[1] == "ascii")
        h.format = PlyFormat::ascii;
      else if (tok[1] == "binary_little_endian")
        h.format = PlyFormat::binary_little_endian;
      else if (tok[1] == "binary_big_endian")
        h.format = PlyFormat::binary_big_endian;
      else
        fail("unknown PLY format " + quote_token(tok[1]));
      if (tok[2] != "1.0")
        fail("unsupported PLY version " + quote_token(tok[2]) + " (expected 1.0)");
    } else if (key == "element") {
      std::uint64_t count = 0;
      if (tok.size() != 3 || !parse_uint(tok[2], count))
        fail("element line must be 'element <name> <count>'");
      PlyElement e;
      e.name = std::string(tok[1]);
      e.count = static_cast<std::size_t>(count);
      e.line = line_no;
      h.elements.push_back(std::move(e));
    } else if (key == "property") {
      if (h.elements.empty()) fail("property before any element");
      PlyProperty p;
      if (tok.size() == 5 && tok[1] == "list") {
        p.is_list = true;
        p.count_type = type_of(tok[2]);
        if (!is_integer(p.count_type))
          fail("list count type " + quote_token(tok[2]) + " is not an integer type");
        p.type = type_of(tok[3]);
        p.name = std::string(tok[4]);
      } else if (tok.size() == 3 && tok[1] != "list") {
        p.type = type_of(tok[1]);
        p.name = std::string(tok[2]);
      } else {
        fail(
            "property line must be 'property <type> <name>' or 'property list <count type> "
            "<item type> <name>'");
      }
      h.elements.back().properties.push_back(std::move(p));
    } else if (key == "end_header") {
      seen_end = true;
    } else {
      fail("unknown header line starting with " + quote_token(key));
    }
  }
  if (!seen_end) {
    ++line_no;
    fail("missing end_header");
  }
  h.end_line = line_no;
  if (!seen_format) fail("missing format line");
  h.data_offset = reader.offset();
  return h;
}

}  // namespace ulc::io
