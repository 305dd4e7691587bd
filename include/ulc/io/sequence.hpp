// Sequence: the frames of one LiDAR, as laid out in a dataset folder (docs/design.md):
//
//   DIR/<lidar>/000000.pcd 000001.pcd ...   frames (.pcd, .ply, .bin), sorted by plain file name
//   DIR/<lidar>/timestamps.txt              optional: one frame start time per line, seconds
//
// A single frame file is accepted as a sequence of one frame (timestamps.txt is then not read).
// Opening lists the frames and their timestamps; frames are loaded one at a time by load_frame,
// which is const and safe to call from several threads.
//
// Frame timestamps (seconds, the LiDAR's own clock), first rule that applies:
//   1. timestamps.txt: its non-blank line count must equal the frame count.
//   2. Per-point times that look absolute (minimum > kAbsoluteTimeThreshold = 1e6 s, i.e. Unix
//      time, as in the real Hesai sample): the frame time is the minimum point time. Deciding
//      this reads frame 0; using it reads every frame once while opening (one at a time) -
//      write a timestamps.txt to avoid that pass.
//   3. File names that are all times: a decimal stem with a fraction ("1645000000.123.pcd",
//      seconds) or an integer stem >= 1e17 (Unix nanoseconds). Zero-padded indices such as
//      "000042" are frame numbers, not times.
//   4. Otherwise 10 Hz: frame i at i * 0.1 s.
// Per-point times: load_frame returns them relative to the frame timestamp (docs/design.md).
// Absolute per-point times are shifted by the frame timestamp; with timestamps.txt they must then
// lie within kMaxPointTimeGap of it (else the two clocks differ and the data are rejected).
// Relative per-point times are returned as stored.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

#include "ulc/io/cloud_file.hpp"
#include "ulc/io/decoded_cloud.hpp"
#include "ulc/io/file_bytes.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/read_stats.hpp"
#include "ulc/io/text_parse.hpp"
#include "ulc/io/written_fields.hpp"

namespace ulc::io {

enum class FrameTimeSource { timestamps_file, point_times, file_name, nominal_rate };

struct FrameInfo {
  std::filesystem::path path;
  double timestamp = 0.0;  ///< seconds, in the LiDAR's own clock
};

template <typename Cloud>
struct Frame {
  Cloud cloud;             ///< per-point times relative to `timestamp`
  double timestamp = 0.0;  ///< seconds, in the LiDAR's own clock
  std::filesystem::path path;
  ReadStats stats;
};

/// Seconds. Absolute per-point times further than this from the timestamps.txt time are an error.
constexpr double kMaxPointTimeGap = 10.0;
/// Seconds between frames when nothing else gives their times (10 Hz).
constexpr double kNominalFramePeriod = 0.1;

namespace detail {

/// Smallest finite per-point time, or NaN when there is none.
inline double min_point_time(const DecodedCloud& c) {
  double lo = std::numeric_limits<double>::infinity();
  for (double t : c.times)
    if (std::isfinite(t)) lo = std::min(lo, t);
  return std::isfinite(lo) ? lo : std::numeric_limits<double>::quiet_NaN();
}

inline bool has_absolute_times(const DecodedCloud& c) {
  return min_point_time(c) > kAbsoluteTimeThreshold;  // false for NaN
}

/// Time encoded in a frame file name (see the rules above), or NaN.
inline double time_from_file_name(const std::filesystem::path& frame) {
  const std::string stem = frame.stem().string();
  double value = 0;
  if (stem.find('.') != std::string::npos)
    return parse_double(stem, value) && std::isfinite(value)
               ? value
               : std::numeric_limits<double>::quiet_NaN();
  std::uint64_t ns = 0;
  if (parse_uint(stem, ns) && ns >= 100000000000000000ull) return static_cast<double>(ns) * 1e-9;
  return std::numeric_limits<double>::quiet_NaN();
}

inline std::vector<double> read_timestamps_file(const std::filesystem::path& path) {
  const std::vector<unsigned char> bytes = read_file_bytes(path);
  ByteReader in(bytes.data(), bytes.size(), path.string());
  std::vector<double> times;
  std::size_t line_no = 0, blank_since = 0;
  std::string_view line;
  while (in.read_line(line)) {
    ++line_no;
    const auto tok = split_tokens(line);
    if (tok.empty()) {
      if (blank_since == 0) blank_since = line_no;
      continue;
    }
    if (blank_since != 0)
      throw IoError(path.string(), at_line(blank_since),
                    "empty line (expected one frame time in seconds per line)");
    double t = 0;
    if (tok.size() != 1 || !parse_double(tok[0], t) || !std::isfinite(t))
      throw IoError(path.string(), at_line(line_no),
                    quote_token(line) + " is not one frame time in seconds");
    times.push_back(t);
  }
  return times;
}

inline std::vector<std::filesystem::path> frame_files(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
    if (entry.is_regular_file() && is_cloud_file_name(entry.path())) files.push_back(entry.path());
  if (ec) throw IoError(dir.string(), "", "cannot list folder: " + ec.message());
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return a.filename().string() < b.filename().string();
  });
  return files;
}

}  // namespace detail

class Sequence {
 public:
  /// Opens a LiDAR's frame folder, or a single frame file. Throws IoError.
  explicit Sequence(const std::filesystem::path& dir_or_file) : path_(dir_or_file) {
    std::error_code ec;
    const auto status = std::filesystem::status(path_, ec);
    if (ec || !std::filesystem::exists(status))
      throw IoError(path_.string(), "", "no such folder or file");
    std::vector<std::filesystem::path> files;
    const bool single = !std::filesystem::is_directory(status);
    if (single) {
      detail::require_cloud_format(path_);
      files.push_back(path_);
    } else {
      files = detail::frame_files(path_);
      if (files.empty())
        throw IoError(path_.string(), "", "no frames (.pcd, .ply or .bin files) in this folder");
    }
    frames_.resize(files.size());
    for (std::size_t i = 0; i < files.size(); ++i) frames_[i].path = files[i];

    const std::filesystem::path stamps = path_ / "timestamps.txt";
    if (!single && std::filesystem::is_regular_file(stamps, ec)) {
      const std::vector<double> times = detail::read_timestamps_file(stamps);
      if (times.size() != frames_.size())
        throw IoError(stamps.string(), "",
                      "has " + std::to_string(times.size()) + " frame times but the folder has " +
                          std::to_string(frames_.size()) + " frames");
      for (std::size_t i = 0; i < frames_.size(); ++i) frames_[i].timestamp = times[i];
      source_ = FrameTimeSource::timestamps_file;
      return;
    }
    if (times_from_points()) return;
    if (times_from_file_names()) return;
    source_ = FrameTimeSource::nominal_rate;
    for (std::size_t i = 0; i < frames_.size(); ++i)
      frames_[i].timestamp = static_cast<double>(i) * kNominalFramePeriod;
  }

  const std::filesystem::path& path() const { return path_; }
  /// The LiDAR's name: the folder name (or the file stem for a single frame).
  std::string name() const {
    const std::filesystem::path p = path_.filename().empty() ? path_.parent_path() : path_;
    return std::filesystem::is_directory(p) ? p.filename().string() : p.stem().string();
  }
  std::size_t size() const { return frames_.size(); }
  const std::vector<FrameInfo>& frames() const { return frames_; }
  FrameTimeSource time_source() const { return source_; }

  const FrameInfo& frame(std::size_t i) const {
    if (i >= frames_.size())
      throw IoError(path_.string(), "",
                    "frame index " + std::to_string(i) + " out of range (" +
                        std::to_string(frames_.size()) + " frames)");
    return frames_[i];
  }

  /// Frame i with per-point times relative to its timestamp (see the rules at the top).
  DecodedCloud load_decoded(std::size_t i, ReadStats* stats = nullptr) const {
    const FrameInfo& info = frame(i);
    DecodedCloud cloud = read_cloud_decoded(info.path, stats);
    if (!detail::has_absolute_times(cloud)) return cloud;
    if (source_ == FrameTimeSource::timestamps_file) {
      const double gap = detail::min_point_time(cloud) - info.timestamp;
      if (std::abs(gap) > kMaxPointTimeGap)
        throw IoError(info.path.string(), "",
                      "absolute per-point times start " + std::to_string(gap) +
                          " s away from the frame time in timestamps.txt (line " +
                          std::to_string(i + 1) + "): different clocks?");
    } else if (source_ != FrameTimeSource::point_times) {
      throw IoError(info.path.string(), "",
                    "has absolute per-point times but frame 0 has none: frame time sources "
                    "cannot be mixed (add a timestamps.txt)");
    }
    for (double& t : cloud.times) t -= info.timestamp;
    return cloud;
  }

  template <typename Cloud>
  Frame<Cloud> load_frame(std::size_t i) const {
    Frame<Cloud> f;
    const DecodedCloud decoded = load_decoded(i, &f.stats);
    f.cloud = to_cloud<Cloud>(decoded);
    f.timestamp = frames_[i].timestamp;
    f.path = frames_[i].path;
    return f;
  }

 private:
  bool times_from_points() {
    DecodedCloud first = read_cloud_decoded(frames_[0].path);
    if (!detail::has_absolute_times(first)) return false;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      if (i > 0) first = read_cloud_decoded(frames_[i].path);
      if (!detail::has_absolute_times(first))
        throw IoError(frames_[i].path.string(), "",
                      "has no absolute per-point times while " + frames_[0].path.string() +
                          " has: cannot time this frame (add a timestamps.txt)");
      frames_[i].timestamp = detail::min_point_time(first);
    }
    source_ = FrameTimeSource::point_times;
    return true;
  }

  bool times_from_file_names() {
    std::vector<double> times;
    for (const FrameInfo& f : frames_) {
      const double t = detail::time_from_file_name(f.path);
      if (!std::isfinite(t)) return false;
      times.push_back(t);
    }
    for (std::size_t i = 0; i < frames_.size(); ++i) frames_[i].timestamp = times[i];
    source_ = FrameTimeSource::file_name;
    return true;
  }

  std::filesystem::path path_;
  std::vector<FrameInfo> frames_;
  FrameTimeSource source_ = FrameTimeSource::nominal_rate;
};

/// The LiDAR folders of a dataset: sub-folders holding at least one frame file, sorted by name.
inline std::vector<std::filesystem::path> list_lidar_folders(const std::filesystem::path& dataset) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dataset, ec))
    throw IoError(dataset.string(), "", "no such dataset folder");
  std::vector<std::filesystem::path> folders;
  for (const auto& entry : std::filesystem::directory_iterator(dataset, ec))
    if (entry.is_directory() && !detail::frame_files(entry.path()).empty())
      folders.push_back(entry.path());
  if (ec) throw IoError(dataset.string(), "", "cannot list folder: " + ec.message());
  if (folders.empty())
    throw IoError(dataset.string(), "",
                  "no LiDAR folders (sub-folders holding .pcd, .ply or .bin frames)");
  std::sort(folders.begin(), folders.end(), [](const auto& a, const auto& b) {
    return a.filename().string() < b.filename().string();
  });
  return folders;
}

}  // namespace ulc::io
