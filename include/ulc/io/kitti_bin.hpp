// KITTI Velodyne .bin: a headerless array of float32 x, y, z, intensity (16 bytes per point,
// little endian). A size that is not a multiple of 16 is an error naming the size; an empty file
// is a valid cloud of zero points. The format has no time field; writers store intensity 0 for
// clouds without one. Non-finite points are dropped and counted, as for PCD.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "ulc/core/point_traits.hpp"
#include "ulc/io/decoded_cloud.hpp"
#include "ulc/io/endian.hpp"
#include "ulc/io/file_bytes.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/read_stats.hpp"

namespace ulc::io {

constexpr std::size_t kKittiPointBytes = 16;

inline DecodedCloud decode_kitti_bin(const unsigned char* data, std::size_t size,
                                     const std::string& file, ReadStats* stats = nullptr) {
  ReadStats local;
  ReadStats& st = stats ? *stats : local;
  st = ReadStats{};
  if (size % kKittiPointBytes != 0)
    throw IoError(file, at_byte(size - size % kKittiPointBytes),
                  "file size " + std::to_string(size) +
                      " bytes is not a multiple of 16 (KITTI .bin holds float32 x y z intensity)");
  const std::size_t n = size / kKittiPointBytes;
  st.format = "kitti_bin";
  st.encoding = "binary";
  st.fields = {"x", "y", "z", "intensity"};
  st.intensity_field = "intensity";
  st.width = n;
  st.height = 1;
  st.points_in_file = n;
  DecodedBuilder out(n, true, false);
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char* p = data + i * kKittiPointBytes;
    out.add(load_le<float>(p), load_le<float>(p + 4), load_le<float>(p + 8), load_le<float>(p + 12),
            0.0);
  }
  return out.finish(st);
}

inline DecodedCloud decode_kitti_bin(const std::vector<unsigned char>& bytes,
                                     const std::string& file, ReadStats* stats = nullptr) {
  return decode_kitti_bin(bytes.data(), bytes.size(), file, stats);
}

inline DecodedCloud read_kitti_bin_decoded(const std::filesystem::path& path,
                                           ReadStats* stats = nullptr) {
  return decode_kitti_bin(read_file_bytes(path), path.string(), stats);
}

/// Reads a KITTI .bin file into any writable cloud type.
template <typename Cloud>
Cloud read_kitti_bin(const std::filesystem::path& path, ReadStats* stats = nullptr) {
  return to_cloud<Cloud>(read_kitti_bin_decoded(path, stats));
}

template <typename Cloud>
std::vector<unsigned char> encode_kitti_bin(const Cloud& cloud) {
  ULC_REQUIRE_CLOUD(Cloud);
  const std::size_t n = traits::size(cloud);
  std::vector<unsigned char> out(n * kKittiPointBytes);
  for (std::size_t i = 0; i < n; ++i) {
    unsigned char* p = out.data() + i * kKittiPointBytes;
    const auto xyz = traits::point(cloud, i);
    for (int a = 0; a < 3; ++a) store_le<float>(p + 4 * a, static_cast<float>(xyz[a]));
    store_le<float>(p + 12, static_cast<float>(traits::intensity(cloud, i)));
  }
  return out;
}

/// Writes `cloud` as KITTI .bin (per-point times, if any, are not stored: the format has none).
template <typename Cloud>
void write_kitti_bin(const std::filesystem::path& path, const Cloud& cloud) {
  write_file_bytes(path, encode_kitti_bin(cloud));
}

}  // namespace ulc::io
