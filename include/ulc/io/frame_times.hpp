// Frame times of a sequence (sequence.hpp): their unit, their order, and the times that frame file
// names encode. The rules, in the words of docs/design.md ("Frame times"):
//
// Unit. Frame times may be written in seconds, milliseconds, microseconds or nanoseconds:
//   - times that look like Unix time (the first one >= 1e8) are read by magnitude: [1e8, 1e11)
//     seconds (years 1973..5138), [1e11, 1e14) milliseconds, [1e14, 1e17) microseconds, beyond
//     nanoseconds - unless that reading puts the frames more than 1000 s apart (nanoseconds
//     counted from 0 pass 1e8 after 0.1 s);
//   - other times (from any origin) by their median step, since a LiDAR's frame period lies in
//     (2 ms, 2 s]: a median step in (0.002, 2] is seconds, (2, 2000] milliseconds, (2e3, 2e6]
//     microseconds, (2e6, 2e9] nanoseconds; anything else is refused. One frame: seconds.
//   Times not in seconds are converted and the reader says so (Sequence::notes).
// Order. Frame times must increase strictly: timestamps.txt is refused at the first line whose
//   time does not come after the previous one; times from names or point times order the frames.
// File names (pcl_ros and friends):
//   - an integer stem with no leading zero and 10, 13, 16 or 19 digits is a Unix time in seconds,
//     milliseconds, microseconds (ROS 1 pointcloud_to_pcd) or nanoseconds; "000042" is a frame
//     number, not a time;
//   - "SEC.FRACTION" is decimal seconds, or SEC seconds + FRACTION nanoseconds when FRACTION is
//     an unpadded nanosecond count (ROS 2 pcl_ros pointcloud_to_pcd writes
//     `stamp.sec << "." << stamp.nanosec`: 1645000000.5000000 is 1645000000 s + 5,000,000 ns).
//     The two readings agree when every fraction has 9 digits (or the times are the same either
//     way: ".0", ".100000000"). Otherwise: a fraction with a
//     leading zero is never an unpadded count (decimal); fractions of one length come from a
//     fixed-precision writer (decimal, unless only the nanosecond reading gives regular frame
//     times); fractions of varying lengths take the one reading that gives regular frame times
//     (strictly increasing, median period in (2 ms, 2 s], no period under half the median) or,
//     when both do, the one whose steps are clearly more even (largest over smallest step less
//     than half the other's: a misread frame lands past the others, like a gap of dropped
//     frames); otherwise they are refused.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "ulc/core/median.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/text_parse.hpp"

namespace ulc::io {

/// Seconds: a LiDAR's frame period lies in (kMinFramePeriod, kMaxFramePeriod].
constexpr double kMinFramePeriod = 0.002;
constexpr double kMaxFramePeriod = 2.0;
/// Times at or above this (in their own unit) are Unix times, read by magnitude ...
constexpr double kUnixTimeThreshold = 1e8;
/// ... unless that reading puts the frames further apart than this (seconds): a capture that
/// saves a frame every few minutes is the slowest we read as such.
constexpr double kMaxSavedFramePeriod = 1000.0;

struct TimeUnit {
  double seconds = 1.0;  ///< seconds per unit
  const char* name = "seconds";
};

inline constexpr TimeUnit kTimeUnits[] = {
    {1.0, "seconds"}, {1e-3, "milliseconds"}, {1e-6, "microseconds"}, {1e-9, "nanoseconds"}};

/// The unit of increasing frame times (see the top); IoError naming `file` when none fits.
inline TimeUnit frame_time_unit(const std::vector<double>& times, const std::string& file,
                                const std::string& what) {
  const double step = median_step(times);
  if (!times.empty() && times.front() >= kUnixTimeThreshold) {
    const double exponent = std::log10(times.front() / kUnixTimeThreshold);
    const auto index = std::min<std::size_t>(3, static_cast<std::size_t>(exponent / 3.0));
    // Unix time, unless that reading puts the frames hours apart (nanoseconds from 0, say).
    if (step * kTimeUnits[index].seconds <= kMaxSavedFramePeriod) return kTimeUnits[index];
  }
  if (times.size() < 2) return kTimeUnits[0];
  for (const TimeUnit& u : kTimeUnits)
    if (step * u.seconds > kMinFramePeriod && step * u.seconds <= kMaxFramePeriod) return u;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%s: the median step between frames is %g, not a LiDAR's frame period (2 ms .. "
                "2 s) in seconds, milliseconds, microseconds or nanoseconds",
                what.c_str(), step);
  throw IoError(file, "", buf);
}

namespace frame_time_detail {

/// A file stem "SEC" or "SEC.FRACTION" (digits only).
struct StemDigits {
  std::string seconds, fraction;
  bool has_fraction = false;
};

inline bool all_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

inline std::optional<StemDigits> stem_digits(const std::filesystem::path& frame) {
  const std::string stem = frame.stem().string();
  StemDigits d;
  const auto dot = stem.find('.');
  d.seconds = stem.substr(0, dot);
  if (dot != std::string::npos) {
    d.has_fraction = true;
    d.fraction = stem.substr(dot + 1);
    if (!all_digits(d.fraction)) return std::nullopt;
  }
  if (!all_digits(d.seconds)) return std::nullopt;
  // Longer than any Unix time in ns (integer) or beyond exact parsing (with a fraction).
  if (d.seconds.size() > (d.has_fraction ? 18u : 19u) || d.fraction.size() > 30)
    return std::nullopt;
  return d;
}

/// An integer stem as a Unix time in seconds (see the top), or NaN.
inline double integer_stem_seconds(const std::string& digits) {
  if (digits.size() > 1 && digits.front() == '0') return std::nan("");  // a frame number
  std::uint64_t value = 0;
  if (!parse_uint(digits, value)) return std::nan("");
  const std::size_t n = digits.size();
  if (n != 10 && n != 13 && n != 16 && n != 19) return std::nan("");
  // Whole seconds and the rest apart, so that the same time in two units gives the same double.
  std::uint64_t per_second = 1;
  for (std::size_t k = 10; k < n; k += 3) per_second *= 1000;
  return static_cast<double>(value / per_second) +
         static_cast<double>(value % per_second) / static_cast<double>(per_second);
}

/// Regular frame times: strictly increasing once sorted, median period in (2 ms, 2 s], no period
/// under half the median (a LiDAR cannot send two frames that close).
inline bool regular(std::vector<double> times) {
  std::sort(times.begin(), times.end());
  const double median = median_step(times);
  if (times.size() >= 2 && !(median > kMinFramePeriod && median <= kMaxFramePeriod)) return false;
  for (std::size_t i = 1; i < times.size(); ++i)
    if (!(times[i] - times[i - 1] >= 0.5 * median && times[i] > times[i - 1])) return false;
  return true;
}

/// Largest step over smallest step of the sorted times (1 for a perfectly regular stream).
inline double step_spread(std::vector<double> times) {
  std::sort(times.begin(), times.end());
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (std::size_t i = 1; i < times.size(); ++i) {
    lo = std::min(lo, times[i] - times[i - 1]);
    hi = std::max(hi, times[i] - times[i - 1]);
  }
  return times.size() < 3 ? 1.0 : hi / lo;
}

/// Chooses between the decimal and the nanosecond reading of "SEC.FRACTION" names (see the top).
inline std::vector<double> choose_fraction_reading(const std::vector<std::filesystem::path>& frames,
                                                   const std::vector<StemDigits>& stems) {
  std::vector<double> decimal, nanoseconds;
  bool nanoseconds_possible = true, same_length = true, all_nine = true;
  for (const StemDigits& d : stems) {
    double value = 0;
    parse_double(d.seconds + "." + d.fraction, value);
    decimal.push_back(value);
    std::uint64_t sec = 0, ns = 0;
    parse_uint(d.seconds, sec);
    const bool count = d.fraction.size() <= 9 && (d.fraction.size() == 1 || d.fraction[0] != '0');
    nanoseconds_possible = nanoseconds_possible && count && parse_uint(d.fraction, ns);
    nanoseconds.push_back(static_cast<double>(sec) + static_cast<double>(ns) * 1e-9);
    same_length = same_length && d.fraction.size() == stems.front().fraction.size();
    all_nine = all_nine && d.fraction.size() == 9;
  }
  bool same_times = true;  // "0" and ".100000000": both readings agree
  for (std::size_t i = 0; i < decimal.size(); ++i)
    same_times = same_times && std::abs(decimal[i] - nanoseconds[i]) < 1e-6;
  if (all_nine || same_times || !nanoseconds_possible) return decimal;
  const bool decimal_regular = regular(decimal), nanoseconds_regular = regular(nanoseconds);
  if (same_length) return decimal_regular || !nanoseconds_regular ? decimal : nanoseconds;
  if (decimal_regular != nanoseconds_regular) return decimal_regular ? decimal : nanoseconds;
  // Both regular: a misread frame lands past the others (a gap of dropped frames, say); keep
  // the reading whose steps are clearly more even.
  const double decimal_spread = step_spread(decimal), nanoseconds_spread = step_spread(nanoseconds);
  if (decimal_regular && nanoseconds_spread * 2.0 < decimal_spread) return nanoseconds;
  if (decimal_regular && decimal_spread * 2.0 < nanoseconds_spread) return decimal;
  throw IoError(
      frames.front().parent_path().string(), "",
      "frame file names such as " + frames.front().filename().string() +
          " read as decimal seconds and as seconds.nanoseconds (pcl_ros) give " +
          (decimal_regular ? "regular frame times both ways" : "irregular frame times both ways") +
          ": cannot tell which; add a timestamps.txt (one time in seconds per frame)");
}

}  // namespace frame_time_detail

/// Seconds encoded in the frame file names (see the top), in the frames' order; nullopt when
/// some name is not a time. Throws IoError when the names are ambiguous.
inline std::optional<std::vector<double>> times_from_file_names(
    const std::vector<std::filesystem::path>& frames) {
  using namespace frame_time_detail;
  std::vector<StemDigits> stems;
  for (const auto& f : frames) {
    auto d = stem_digits(f);
    if (!d || d->has_fraction != (stems.empty() ? d->has_fraction : stems.front().has_fraction))
      return std::nullopt;
    stems.push_back(*d);
  }
  if (stems.empty()) return std::nullopt;
  if (stems.front().has_fraction) return choose_fraction_reading(frames, stems);
  std::vector<double> times;
  for (const StemDigits& d : stems) {
    times.push_back(integer_stem_seconds(d.seconds));
    if (std::isnan(times.back())) return std::nullopt;
  }
  return times;
}

}  // namespace ulc::io
