// read_cloud / write_cloud: one entry point for every point-cloud file, chosen by extension
// (case-insensitive): .pcd, .ply, .bin (KITTI). Anything else is an IoError.
// write_cloud writes PCD as DATA binary and PLY as binary_little_endian.
#pragma once

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>
#include <string>

#include "ulc/io/decoded_cloud.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/kitti_bin.hpp"
#include "ulc/io/pcd.hpp"
#include "ulc/io/ply.hpp"
#include "ulc/io/read_stats.hpp"

namespace ulc::io {

enum class CloudFormat { pcd, ply, kitti_bin };

/// The format a file name stands for, or nullopt.
inline std::optional<CloudFormat> cloud_format_of(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".pcd") return CloudFormat::pcd;
  if (ext == ".ply") return CloudFormat::ply;
  if (ext == ".bin") return CloudFormat::kitti_bin;
  return std::nullopt;
}

inline bool is_cloud_file_name(const std::filesystem::path& path) {
  return cloud_format_of(path).has_value();
}

namespace detail {
inline CloudFormat require_cloud_format(const std::filesystem::path& path) {
  const auto format = cloud_format_of(path);
  if (!format)
    throw IoError(path.string(), "",
                  "unknown point-cloud file extension " + quote_token(path.extension().string()) +
                      " (expected .pcd, .ply or .bin)");
  return *format;
}
}  // namespace detail

inline DecodedCloud read_cloud_decoded(const std::filesystem::path& path,
                                       ReadStats* stats = nullptr) {
  switch (detail::require_cloud_format(path)) {
    case CloudFormat::pcd:
      return read_pcd_decoded(path, stats);
    case CloudFormat::ply:
      return read_ply_decoded(path, stats);
    case CloudFormat::kitti_bin:
      return read_kitti_bin_decoded(path, stats);
  }
  return {};
}

/// Reads any supported point-cloud file into any writable cloud type.
template <typename Cloud>
Cloud read_cloud(const std::filesystem::path& path, ReadStats* stats = nullptr) {
  return to_cloud<Cloud>(read_cloud_decoded(path, stats));
}

/// Writes `cloud` in the format its extension names.
template <typename Cloud>
void write_cloud(const std::filesystem::path& path, const Cloud& cloud) {
  switch (detail::require_cloud_format(path)) {
    case CloudFormat::pcd:
      write_pcd(path, cloud, PcdEncoding::binary);
      return;
    case CloudFormat::ply:
      write_ply(path, cloud, PlyFormat::binary_little_endian);
      return;
    case CloudFormat::kitti_bin:
      write_kitti_bin(path, cloud);
      return;
  }
}

}  // namespace ulc::io
