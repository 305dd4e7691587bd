// PLY writer: ascii, binary_little_endian (default) or binary_big_endian, format 1.0.
//
// One `vertex` element with float x y z, then float intensity and t (seconds; double for
// absolute times) when the cloud has them, the same fields as the PCD writer (written_fields.hpp).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "ulc/core/point_traits.hpp"
#include "ulc/io/endian.hpp"
#include "ulc/io/file_bytes.hpp"
#include "ulc/io/ply_header.hpp"
#include "ulc/io/written_fields.hpp"

namespace ulc::io {

/// The bytes of a PLY file holding `cloud`.
template <typename Cloud>
std::vector<unsigned char> encode_ply(const Cloud& cloud,
                                      PlyFormat format = PlyFormat::binary_little_endian) {
  ULC_REQUIRE_CLOUD(Cloud);
  using detail::OutFieldSpec;
  const std::size_t n = traits::size(cloud);
  const std::vector<OutFieldSpec> specs = detail::out_field_specs(written_fields(cloud));
  std::string header = std::string("ply\nformat ") + to_string(format) +
                       " 1.0\ncomment written by ULC\nelement vertex " + std::to_string(n) + "\n";
  std::size_t point_bytes = 0;
  for (const OutFieldSpec& s : specs) {
    header += std::string("property ") + (s.size == 8 ? "double " : "float ") + s.name + "\n";
    point_bytes += s.size;
  }
  header += "end_header\n";
  std::vector<unsigned char> out(header.begin(), header.end());

  if (format == PlyFormat::ascii) {
    const std::string text = detail::ascii_rows(cloud, specs);
    out.insert(out.end(), text.begin(), text.end());
    return out;
  }
  const Endian order = format == PlyFormat::binary_big_endian ? Endian::big : Endian::little;
  const std::size_t start = out.size();
  out.resize(start + n * point_bytes);
  unsigned char* p = out.data() + start;
  for (std::size_t i = 0; i < n; ++i) {
    for (const OutFieldSpec& s : specs) {
      detail::put_value(p, detail::out_value(cloud, i, s.field), s.size, order);
      p += s.size;
    }
  }
  return out;
}

/// Writes `cloud` as a PLY file (binary little endian unless told otherwise).
template <typename Cloud>
void write_ply(const std::filesystem::path& path, const Cloud& cloud,
               PlyFormat format = PlyFormat::binary_little_endian) {
  write_file_bytes(path, encode_ply(cloud, format));
}

}  // namespace ulc::io
