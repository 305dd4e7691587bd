// PCD v0.7 writer: DATA binary (default), binary_compressed (our LZF encoder) or ascii.
//
// Fields: x y z float32, then intensity float32 and t (seconds; float32, or float64 for absolute
// times) when the cloud has them (see written_fields.hpp). One unorganised row: WIDTH = POINTS,
// HEIGHT = 1. Float data round-trips exactly through every encoding.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "ulc/core/point_traits.hpp"
#include "ulc/io/endian.hpp"
#include "ulc/io/file_bytes.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/lzf.hpp"
#include "ulc/io/pcd_header.hpp"
#include "ulc/io/written_fields.hpp"

namespace ulc::io {

namespace detail {

inline std::string pcd_header_text(std::size_t n, const std::vector<OutFieldSpec>& specs,
                                   PcdEncoding e) {
  std::string fields, sizes, types, counts;
  for (const OutFieldSpec& s : specs) {
    const char* sep = fields.empty() ? "" : " ";
    fields += sep + std::string(s.name);
    sizes += sep + std::to_string(s.size);
    types += sep + std::string("F");
    counts += sep + std::string("1");
  }
  const std::string count = std::to_string(n);
  return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " +
         sizes + "\nTYPE " + types + "\nCOUNT " + counts + "\nWIDTH " + count +
         "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + count + "\nDATA " + to_string(e) + "\n";
}

}  // namespace detail

/// The bytes of a PCD file holding `cloud`; `file` names the destination in errors.
template <typename Cloud>
std::vector<unsigned char> encode_pcd(const Cloud& cloud,
                                      PcdEncoding encoding = PcdEncoding::binary,
                                      const std::string& file = "<pcd in memory>") {
  ULC_REQUIRE_CLOUD(Cloud);
  using detail::OutFieldSpec;
  const std::size_t n = traits::size(cloud);
  const std::vector<OutFieldSpec> specs = detail::out_field_specs(written_fields(cloud));
  std::size_t point_bytes = 0;
  for (const OutFieldSpec& s : specs) point_bytes += s.size;

  const std::string header = detail::pcd_header_text(n, specs, encoding);
  std::vector<unsigned char> out(header.begin(), header.end());
  if (encoding == PcdEncoding::ascii) {
    const std::string text = detail::ascii_rows(cloud, specs);
    out.insert(out.end(), text.begin(), text.end());
    return out;
  }

  std::vector<unsigned char> data(n * point_bytes);
  if (encoding == PcdEncoding::binary) {
    for (std::size_t i = 0; i < n; ++i) {
      unsigned char* p = data.data() + i * point_bytes;
      for (const OutFieldSpec& s : specs) {
        detail::put_value(p, detail::out_value(cloud, i, s.field), s.size, Endian::little);
        p += s.size;
      }
    }
    out.insert(out.end(), data.begin(), data.end());
    return out;
  }

  // binary_compressed: field-major layout, then LZF.
  unsigned char* column = data.data();
  for (const OutFieldSpec& s : specs) {
    for (std::size_t i = 0; i < n; ++i)
      detail::put_value(column + i * s.size, detail::out_value(cloud, i, s.field), s.size,
                        Endian::little);
    column += n * s.size;
  }
  const std::vector<unsigned char> packed = lzf_compress(data);
  if (data.size() > UINT32_MAX || packed.size() > UINT32_MAX)
    throw IoError(file, "", "cloud too large for binary_compressed (4 GiB limit)");
  unsigned char sizes[8];
  store_le<std::uint32_t>(sizes, static_cast<std::uint32_t>(packed.size()));
  store_le<std::uint32_t>(sizes + 4, static_cast<std::uint32_t>(data.size()));
  out.insert(out.end(), sizes, sizes + 8);
  out.insert(out.end(), packed.begin(), packed.end());
  return out;
}

/// Writes `cloud` as a PCD file (binary unless told otherwise).
template <typename Cloud>
void write_pcd(const std::filesystem::path& path, const Cloud& cloud,
               PcdEncoding encoding = PcdEncoding::binary) {
  write_file_bytes(path, encode_pcd(cloud, encoding, path.string()));
}

}  // namespace ulc::io
