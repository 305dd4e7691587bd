// open_recording: any recording ULC reads, as one MessageSource.
//
//   FILE.bag        ROS 1 bag (format 2.0)
//   FILE.mcap       MCAP (ROS 2's default storage; ROS 1 messages in MCAP too)
//   FILE.db3        rosbag2 SQLite storage, one file
//   FOLDER          a rosbag2 bag: metadata.yaml and its .mcap / .db3 files (split bags merged)
// A file is recognised by its first bytes, whatever its extension; the extension only decides
// whether a path names a recording at all (is_recording_path), for the command line.
#pragma once

#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "ulc/bags/mcap_reader.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/bags/ros1_bag.hpp"
#include "ulc/bags/rosbag2_folder.hpp"
#include "ulc/bags/rosbag2_sqlite.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

enum class RecordingFormat { ros1_bag, mcap, sqlite };

namespace detail {

inline std::string lower_extension(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

inline RecordingFormat sniff_format(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw io::IoError(file.string(), "", "cannot open for reading");
  std::array<char, 16> head{};
  in.read(head.data(), head.size());
  const auto got = static_cast<std::size_t>(in.gcount());
  if (got == 0) throw io::IoError(file.string(), "", "empty file: not a recording");
  const auto starts = [&](const char* magic, std::size_t n) {
    return got >= n && std::memcmp(head.data(), magic, n) == 0;
  };
  if (starts("#ROSBAG V", 9)) return RecordingFormat::ros1_bag;
  if (starts("\x89MCAP", 5)) return RecordingFormat::mcap;
  if (starts("SQLite format 3", 16)) return RecordingFormat::sqlite;
  throw io::IoError(file.string(), io::at_byte(0),
                    "not a recording: expected a ROS 1 bag, an MCAP file or a rosbag2 .db3");
}

}  // namespace detail

/// True when `path` names a recording rather than a cloud file or a frame folder: a .bag, .mcap
/// or .db3 file, or a folder holding metadata.yaml or .db3 / .mcap files.
inline bool is_recording_path(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    if (std::filesystem::exists(path / "metadata.yaml", ec)) return true;
    for (const auto& entry : std::filesystem::directory_iterator(path, ec)) {
      const std::string ext = detail::lower_extension(entry.path());
      if (ext == ".db3" || ext == ".mcap") return true;
    }
    return false;
  }
  const std::string ext = detail::lower_extension(path);
  return ext == ".bag" || ext == ".mcap" || ext == ".db3";
}

/// Opens one recording file, recognised by its first bytes.
inline std::unique_ptr<MessageSource> open_recording_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw io::IoError(file.string(), "", "no such file");
  switch (detail::sniff_format(file)) {
    case RecordingFormat::ros1_bag:
      return std::make_unique<Ros1Bag>(file);
    case RecordingFormat::mcap:
      return std::make_unique<McapReader>(file);
    case RecordingFormat::sqlite:
      return std::make_unique<Rosbag2Sqlite>(file);
  }
  return nullptr;
}

/// Opens a recording file or a rosbag2 folder.
inline std::unique_ptr<MessageSource> open_recording(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw io::IoError(path.string(), "", "no such file or folder");
  if (std::filesystem::is_directory(path, ec))
    return open_rosbag2_folder(path, open_recording_file);
  return open_recording_file(path);
}

}  // namespace ulc::bags
