// Sequence: the frames of one LiDAR, as laid out in a dataset folder (docs/design.md):
//
//   DIR/<lidar>/000000.pcd 000001.pcd ...   frames (.pcd, .ply, .bin), in time order
//   DIR/<lidar>/timestamps.txt              optional: one frame start time per line
//
// A single frame file is accepted as a sequence of one frame (timestamps.txt is then not read).
// Opening lists the frames and their timestamps; frames are loaded one at a time by load_frame,
// which is const and safe to call from several threads.
//
// Frame timestamps (seconds, the LiDAR's own clock), first rule that applies:
//   1. timestamps.txt: its non-blank line count must equal the frame count; line i is the frame
//      i in file-name order, and the times must increase strictly (else refused at the line).
//   2. Per-point times that look absolute (minimum > kAbsoluteTimeThreshold = 1e6, i.e. Unix
//      time, as in the real Hesai sample): the frame time is the minimum point time. Deciding
//      this reads frame 0; using it reads every frame once while opening (one at a time) -
//      write a timestamps.txt to avoid that pass.
//   3. File names that are all times (frame_times.hpp): "1645000000.123.pcd" (decimal seconds),
//      "1645000000.5000000.pcd" (pcl_ros: seconds.unpadded nanoseconds), or Unix times in s, ms,
//      us or ns ("1645000000123456789.pcd"). Zero-padded indices such as "000042" are frame
//      numbers, not times.
//   4. Otherwise 10 Hz: frame i at i * 0.1 s, and notes() says so.
// With rules 2 and 3 the frames are ordered by time, not by name, and two frames with the same
// time are refused. Times in ms, us or ns are converted to seconds by the rule of frame_times.hpp
// (Unix-time magnitude, else the median frame period) and notes() says so.
// Per-point times: load_decoded returns them relative to the frame timestamp (docs/design.md).
// Absolute per-point times (their unit by magnitude) are shifted by the frame timestamp; with
// timestamps.txt they must then lie within kMaxPointTimeGap of it (else the two clocks differ and
// the data are rejected). Relative per-point times are returned as stored, in seconds: a float
// time field whose sweep (frame 0's span of point times) exceeds kMaxFramePeriod is read as ms,
// us or ns, whichever brings the sweep under it, and notes() says so.
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
#include "ulc/io/frame_times.hpp"
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

/// Largest minus smallest finite per-point time; 0 when there are none.
inline double point_time_span(const DecodedCloud& c) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double t : c.times)
    if (std::isfinite(t)) lo = std::min(lo, t), hi = std::max(hi, t);
  return hi > lo ? hi - lo : 0.0;
}

/// Shortest decimal form of a time, for messages.
inline std::string format_time(double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.15g", t);
  return buf;
}

/// The unit of absolute per-point times: by magnitude (frame_times.hpp), seconds below 1e8.
inline TimeUnit absolute_point_time_unit(double min_time) {
  return frame_time_unit({min_time}, "", "");
}

inline bool has_absolute_times(const DecodedCloud& c) {
  return min_point_time(c) > kAbsoluteTimeThreshold;  // false for NaN
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

/// Refuses timestamps.txt at the first line whose time does not come after the previous line's.
inline void require_increasing_lines(const std::vector<double>& times,
                                     const std::filesystem::path& path) {
  for (std::size_t i = 1; i < times.size(); ++i)
    if (!(times[i] > times[i - 1]))
      throw IoError(path.string(), at_line(i + 1),
                    "time " + format_time(times[i]) +
                        (times[i] == times[i - 1] ? " repeats" : " goes back from") +
                        " the previous line's " + format_time(times[i - 1]) +
                        " (frame times must increase)");
}

inline std::vector<std::filesystem::path> frame_files(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
    if (entry.is_regular_file() && is_cloud_file_name(entry.path())) files.push_back(entry.path());
  if (ec) throw IoError(dir.string(), "", "cannot list folder: " + ec.message());
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return a.filename().string() < b.filename().string();
  });  // time order, when the names carry no times
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
    const DecodedCloud first = read_cloud_decoded(frames_[0].path);
    const std::filesystem::path stamps = path_ / "timestamps.txt";
    if (!single && std::filesystem::is_regular_file(stamps, ec))
      times_from_file(stamps);
    else if (!times_from_points(first) && !times_from_names())
      times_from_nominal_rate();
    choose_relative_point_time_unit(first);
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
  /// What the reader assumed or converted (a rate, a unit), one sentence each starting with the
  /// file or folder it concerns, for the user.
  const std::vector<std::string>& notes() const { return notes_; }

  const FrameInfo& frame(std::size_t i) const {
    if (i >= frames_.size())
      throw IoError(path_.string(), "",
                    "frame index " + std::to_string(i) + " out of range (" +
                        std::to_string(frames_.size()) + " frames)");
    return frames_[i];
  }

  /// Frame i with per-point times relative to its timestamp, in seconds (see the top).
  DecodedCloud load_decoded(std::size_t i, ReadStats* stats = nullptr) const {
    const FrameInfo& info = frame(i);
    DecodedCloud cloud = read_cloud_decoded(info.path, stats);
    if (!detail::has_absolute_times(cloud)) {
      if (relative_point_time_unit_ != 1.0)
        for (double& t : cloud.times) t *= relative_point_time_unit_;
      return cloud;
    }
    const double unit = detail::absolute_point_time_unit(detail::min_point_time(cloud)).seconds;
    if (source_ == FrameTimeSource::timestamps_file) {
      const double gap = detail::min_point_time(cloud) * unit - info.timestamp;
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
    for (double& t : cloud.times) t = t * unit - info.timestamp;
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
  void times_from_file(const std::filesystem::path& stamps) {
    std::vector<double> times = detail::read_timestamps_file(stamps);
    if (times.size() != frames_.size())
      throw IoError(stamps.string(), "",
                    "has " + std::to_string(times.size()) + " frame times but the folder has " +
                        std::to_string(frames_.size()) + " frames");
    detail::require_increasing_lines(times, stamps);
    const double unit = seconds_per_unit(times, stamps.string(), "frame times");
    for (std::size_t i = 0; i < frames_.size(); ++i) frames_[i].timestamp = times[i] * unit;
    source_ = FrameTimeSource::timestamps_file;
  }

  bool times_from_points(const DecodedCloud& first) {
    if (!detail::has_absolute_times(first)) return false;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      const DecodedCloud c = i == 0 ? DecodedCloud{} : read_cloud_decoded(frames_[i].path);
      const DecodedCloud& frame = i == 0 ? first : c;
      if (!detail::has_absolute_times(frame))
        throw IoError(frames_[i].path.string(), "",
                      "has no absolute per-point times while " + frames_[0].path.string() +
                          " has: cannot time this frame (add a timestamps.txt)");
      const double t = detail::min_point_time(frame);
      frames_[i].timestamp = t * detail::absolute_point_time_unit(t).seconds;
    }
    source_ = FrameTimeSource::point_times;
    order_by_time();
    return true;
  }

  bool times_from_names() {
    std::vector<std::filesystem::path> files;
    for (const FrameInfo& f : frames_) files.push_back(f.path);
    auto times = times_from_file_names(files);
    if (!times) return false;
    const double unit = seconds_per_unit(*times, path_.string(), "frame times in the file names");
    for (std::size_t i = 0; i < frames_.size(); ++i) frames_[i].timestamp = (*times)[i] * unit;
    source_ = FrameTimeSource::file_name;
    order_by_time();
    return true;
  }

  void times_from_nominal_rate() {
    source_ = FrameTimeSource::nominal_rate;
    for (std::size_t i = 0; i < frames_.size(); ++i)
      frames_[i].timestamp = static_cast<double>(i) * kNominalFramePeriod;
    if (frames_.size() > 1)
      notes_.push_back(
          path_.string() +
          ": no frame times (no timestamps.txt, no absolute per-point times, no times in the file "
          "names): assuming 10 Hz, frame i at i * 0.1 s in file-name order; write a "
          "timestamps.txt if that is wrong");
  }

  /// Seconds per unit of `times` (frame_times.hpp), noted when the unit is not seconds.
  double seconds_per_unit(std::vector<double> times, const std::string& file,
                          const std::string& what) {
    std::sort(times.begin(), times.end());
    const TimeUnit unit = frame_time_unit(times, file, what);
    if (unit.seconds != 1.0)
      notes_.push_back(file + ": " + what + " read as " + unit.name + " and converted to seconds");
    return unit.seconds;
  }

  /// Sorts the frames by time; refuses two frames with the same time, and frames whose median
  /// period is no LiDAR's (under 2 ms) nor a slow capture's (up to 1000 s).
  void order_by_time() {
    std::stable_sort(frames_.begin(), frames_.end(), [](const FrameInfo& a, const FrameInfo& b) {
      return a.timestamp < b.timestamp;
    });
    for (std::size_t i = 1; i < frames_.size(); ++i)
      if (!(frames_[i].timestamp > frames_[i - 1].timestamp))
        throw IoError(frames_[i].path.string(), "",
                      "has the same frame time (" + detail::format_time(frames_[i].timestamp) +
                          " s) as " + frames_[i - 1].path.filename().string());
    std::vector<double> times;
    for (const FrameInfo& f : frames_) times.push_back(f.timestamp);
    const double step = median_step(times);
    if (frames_.size() > 1 && !(step > kMinFramePeriod && step <= kMaxSavedFramePeriod))
      throw IoError(
          path_.string(), "",
          "frame times " +
              std::string(source_ == FrameTimeSource::file_name ? "in the file names"
                                                                : "from the per-point times") +
              " are " + detail::format_time(step) +
              " s apart (median): not a LiDAR's frame period; add a timestamps.txt");
  }

  /// Relative per-point times whose sweep in frame 0 exceeds kMaxFramePeriod are not seconds.
  void choose_relative_point_time_unit(const DecodedCloud& first) {
    if (detail::has_absolute_times(first)) return;
    const double span = detail::point_time_span(first);
    if (span <= kMaxFramePeriod) return;
    for (const TimeUnit& u : kTimeUnits)
      if (span * u.seconds <= kMaxFramePeriod) {
        relative_point_time_unit_ = u.seconds;
        notes_.push_back(frames_[0].path.string() + ": per-point times span " +
                         detail::format_time(span) + " in one frame: read as " + u.name +
                         " and converted to seconds");
        return;
      }
    throw IoError(frames_[0].path.string(), "",
                  "per-point times span " + detail::format_time(span) +
                      " in one frame: not a sweep in seconds, ms, us or ns");
  }

  std::filesystem::path path_;
  std::vector<FrameInfo> frames_;
  FrameTimeSource source_ = FrameTimeSource::nominal_rate;
  double relative_point_time_unit_ = 1.0;  ///< seconds per stored unit
  std::vector<std::string> notes_;
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
