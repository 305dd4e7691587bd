// rosbag2 bag folders: which files make up a bag, and the bag opened as one MessageSource.
//
// A rosbag2 bag is a folder. Its metadata.yaml lists the files under
// rosbag2_bagfile_information.relative_file_paths, in recording order, with the storage plugin in
// storage_identifier ("sqlite3", "mcap"). Bags of metadata version < 4 wrote those paths with the
// bag folder's name in front ("my_bag/my_bag_0.db3"); later ones relative to the folder. Both are
// accepted: a listed path is looked up in the folder as written, then by its file name alone,
// then (old bags that omitted it) with the storage's extension appended.
// A folder without metadata.yaml (a recording cut short) is read as every *.db3 and *.mcap file
// in it, in natural order (wbag_2 before wbag_10).
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "ulc/bags/merged_source.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

/// What ULC needs from a rosbag2 metadata.yaml.
struct Rosbag2Metadata {
  std::string storage_identifier;            ///< "sqlite3", "mcap" (may be empty in old bags)
  std::vector<std::filesystem::path> files;  ///< existing files, in the listed order
};

namespace rosbag2_detail {

inline bool is_digit(char c) {
  return std::isdigit(static_cast<unsigned char>(c)) != 0;
}

/// The end of the digit run starting at `i`.
inline std::size_t digits_end(const std::string& s, std::size_t i) {
  while (i < s.size() && is_digit(s[i])) ++i;
  return i;
}

/// Compares the numbers a[i, ei) and b[j, ej) by value (leading zeros ignored): <0, 0, >0.
inline int compare_numbers(const std::string& a, std::size_t i, std::size_t ei,
                           const std::string& b, std::size_t j, std::size_t ej) {
  while (i + 1 < ei && a[i] == '0') ++i;
  while (j + 1 < ej && b[j] == '0') ++j;
  if (ei - i != ej - j) return ei - i < ej - j ? -1 : 1;  // more digits: larger
  return a.compare(i, ei - i, b, j, ej - j);
}

/// <0, 0, >0 as a sorts before, with, after b, digit runs compared as numbers.
inline int natural_compare(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      const std::size_t ei = digits_end(a, i), ej = digits_end(b, j);
      if (const int order = compare_numbers(a, i, ei, b, j, ej); order != 0) return order;
      i = ei, j = ej;
    } else if (a[i] != b[j]) {
      return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]) ? -1 : 1;
    } else {
      ++i, ++j;
    }
  }
  const std::size_t rest_a = a.size() - i, rest_b = b.size() - j;
  return rest_a == rest_b ? 0 : (rest_a < rest_b ? -1 : 1);
}

/// a < b with digit runs compared as numbers: "wbag_2" < "wbag_10". Names equal as numbers
/// ("wbag_002", "wbag_2") fall back to plain order.
inline bool natural_less(const std::string& a, const std::string& b) {
  const int order = natural_compare(a, b);
  return order != 0 ? order < 0 : a < b;
}

/// Every *.db3 and *.mcap file in `folder`, in natural order.
inline std::vector<std::filesystem::path> storage_files(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const auto ext = entry.path().extension();
    if ((ext == ".db3" || ext == ".mcap") && entry.is_regular_file(ec))
      files.push_back(entry.path());
  }
  if (ec) throw io::IoError(folder.string(), "", "cannot list the folder: " + ec.message());
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  return files;
}

inline std::string extension_of_storage(const std::string& storage_identifier) {
  if (storage_identifier == "sqlite3") return ".db3";
  if (storage_identifier == "mcap") return ".mcap";
  return {};
}

/// Where the listed `relative` file is (see the file comment), or an empty path.
inline std::filesystem::path locate(const std::filesystem::path& folder,
                                    const std::filesystem::path& relative,
                                    const std::string& extension) {
  std::vector<std::filesystem::path> candidates{folder / relative, folder / relative.filename()};
  if (!extension.empty() && relative.extension() != extension)
    candidates.push_back(folder / (relative.filename().string() + extension));
  std::error_code ec;
  for (const auto& c : candidates)
    if (std::filesystem::is_regular_file(c, ec)) return c;
  return {};
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw io::IoError(path.string(), "", "cannot read the file");
  return text.str();
}

/// The line of a node (1-based) for errors, "" when yaml-cpp has none.
inline std::string line_of(const YAML::Mark& mark) {
  return mark.is_null() ? std::string() : io::at_line(static_cast<std::size_t>(mark.line) + 1);
}

/// map[key] when present, else a null node (yaml-cpp's nodes for missing keys throw when used).
inline YAML::Node child(const YAML::Node& map, const char* key) {
  if (!map.IsMap()) return YAML::Node();
  const YAML::Node value = map[key];
  return value.IsDefined() ? value : YAML::Node();
}

inline std::string scalar_or_empty(const YAML::Node& map, const char* key) {
  const YAML::Node value = child(map, key);
  return value.IsScalar() ? value.Scalar() : std::string();
}

/// The parsed rosbag2_bagfile_information map.
inline YAML::Node bagfile_information(const std::filesystem::path& metadata) {
  YAML::Node root;
  try {
    root = YAML::Load(read_text(metadata));
  } catch (const YAML::Exception& e) {
    throw io::IoError(metadata.string(), line_of(e.mark), "not valid YAML: " + e.msg);
  }
  const YAML::Node info = child(root, "rosbag2_bagfile_information");
  if (!info.IsMap()) throw io::IoError(metadata.string(), "", "no rosbag2_bagfile_information map");
  return info;
}

}  // namespace rosbag2_detail

/// Reads `folder`/metadata.yaml; IoError naming metadata.yaml when it is not YAML, lacks
/// relative_file_paths, names a file that is not there, or describes a compressed bag.
inline Rosbag2Metadata read_rosbag2_metadata(const std::filesystem::path& folder) {
  namespace d = rosbag2_detail;
  const auto metadata = folder / "metadata.yaml";
  const std::string name = metadata.string();
  Rosbag2Metadata out;
  try {
    const YAML::Node info = d::bagfile_information(metadata);
    out.storage_identifier = d::scalar_or_empty(info, "storage_identifier");
    const std::string mode = d::scalar_or_empty(info, "compression_mode");
    if (!mode.empty() && mode != "none" && mode != "NONE")
      throw io::IoError(name, "",
                        "compressed rosbag2 bags (compression_mode " + mode +
                            ") are not supported; decompress it with ros2 bag convert");
    const YAML::Node paths = d::child(info, "relative_file_paths");
    if (!paths.IsSequence() || paths.size() == 0)
      throw io::IoError(name, d::line_of(paths.Mark()), "no relative_file_paths list");
    const std::string extension = d::extension_of_storage(out.storage_identifier);
    for (const YAML::Node& entry : paths) {
      if (!entry.IsScalar() || entry.Scalar().empty())
        throw io::IoError(name, d::line_of(entry.Mark()), "relative_file_paths: not a file name");
      auto found = d::locate(folder, entry.Scalar(), extension);
      if (found.empty())
        throw io::IoError(name, d::line_of(entry.Mark()),
                          "lists " + entry.Scalar() + ", which is not in " + folder.string());
      out.files.push_back(std::move(found));
    }
  } catch (const YAML::Exception& e) {  // a conversion on a malformed document
    throw io::IoError(name, d::line_of(e.mark), e.msg);
  }
  return out;
}

/// The bag's files in order: from metadata.yaml, or every *.db3 / *.mcap file when it has none.
inline std::vector<std::filesystem::path> rosbag2_files(const std::filesystem::path& folder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    throw io::IoError(folder.string(), "", "not a folder (a rosbag2 bag is a folder)");
  if (std::filesystem::exists(folder / "metadata.yaml", ec))
    return read_rosbag2_metadata(folder).files;
  auto files = rosbag2_detail::storage_files(folder);
  if (files.empty())
    throw io::IoError(folder.string(), "", "no metadata.yaml and no .db3 or .mcap file");
  return files;
}

/// The bag in `folder` as one MessageSource: `open_file` opens each file (a Rosbag2Sqlite, an
/// MCAP reader, ...); several files are merged in time order, a single one is returned as is.
inline std::unique_ptr<MessageSource> open_rosbag2_folder(
    const std::filesystem::path& folder,
    const std::function<std::unique_ptr<MessageSource>(const std::filesystem::path&)>& open_file) {
  const auto files = rosbag2_files(folder);
  std::vector<std::unique_ptr<MessageSource>> parts;
  std::vector<std::string> names;
  for (const auto& file : files) {
    parts.push_back(open_file(file));
    names.push_back(file.string());
  }
  if (parts.size() == 1) return std::move(parts.front());
  return std::make_unique<MergedSource>(std::move(parts), std::move(names));
}

}  // namespace ulc::bags
