// Per-point times of recorded clouds, turned into ULC's convention: seconds relative to the
// frame's time (header.stamp), as the design notes define for every cloud.
//
// Drivers store them differently: Velodyne `time` float32 seconds relative to the stamp, Ouster
// `t` uint32 nanoseconds relative, Livox `offset_time` uint32 nanoseconds relative (to the
// message's `timebase`, for CustomMsg), Hesai and RoboSense `timestamp` float64 absolute
// seconds, livox_ros_driver2 `timestamp` float64 absolute nanoseconds. Whether a field is
// absolute or relative is decided from its values, never from its name alone:
//   absolute  the smallest value, read in seconds, milliseconds, microseconds or nanoseconds,
//             lies within kAbsoluteMatchSeconds of header.stamp (the unit that comes closest);
//   relative  otherwise, in seconds for a floating-point field and nanoseconds for an integer
//             one, provided the values span less than kMaxSweepSeconds and start within it of 0;
//   none      every value is 0 (drivers that leave the field empty): the cloud has no times.
// Anything else is an error that names the field and its range: a unit cannot be guessed.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "ulc/io/scalar_type.hpp"

namespace ulc::bags {

/// Absolute point times must start this close to header.stamp (seconds).
constexpr double kAbsoluteMatchSeconds = 10.0;
/// Relative point times must span less than this and start within it of the stamp (seconds).
constexpr double kMaxSweepSeconds = 10.0;

enum class TimeReference { none, relative, absolute };

struct PointTimeInfo {
  std::string field;  ///< empty: the message has no time field
  io::ScalarType type = io::ScalarType::float32;
  double seconds_per_unit = 1.0;
  TimeReference reference = TimeReference::none;
  std::string note;  ///< what was worked around, for the user (empty when nothing)
};

inline const char* unit_name(double seconds_per_unit) {
  if (seconds_per_unit == 1.0) return "seconds";
  if (seconds_per_unit == 1e-3) return "milliseconds";
  if (seconds_per_unit == 1e-6) return "microseconds";
  return "nanoseconds";
}

inline const char* type_name(io::ScalarType t) {
  static constexpr const char* kNames[] = {"int8",   "uint8", "int16",  "uint16",  "int32",
                                           "uint32", "int64", "uint64", "float32", "float64"};
  return kNames[static_cast<int>(t)];
}

/// "`t` uint32 nanoseconds relative to header.stamp", "none", ...
inline std::string describe(const PointTimeInfo& info) {
  if (info.field.empty()) return "none";
  std::string out = "`" + info.field + "` " + type_name(info.type) + " ";
  if (info.reference == TimeReference::none) return out + "all zero: ignored";
  out += unit_name(info.seconds_per_unit);
  out += info.reference == TimeReference::absolute ? " absolute (made relative to header.stamp)"
                                                   : " relative to header.stamp";
  return info.note.empty() ? out : out + "; " + info.note;
}

namespace detail {

/// The unit whose reading of `lo` comes closest to the stamp, if within kAbsoluteMatchSeconds.
inline double absolute_unit(double lo, double hi, double stamp_s) {
  double best = 0.0, best_gap = kAbsoluteMatchSeconds;
  for (const double unit : {1.0, 1e-3, 1e-6, 1e-9}) {
    const double gap = std::abs(lo * unit - stamp_s);
    if (gap < best_gap && (hi - lo) * unit < kMaxSweepSeconds) {
      best = unit;
      best_gap = gap;
    }
  }
  // A stamp near 0 (a simulated clock) cannot tell absolute from relative: relative wins there.
  return std::abs(stamp_s) > kAbsoluteMatchSeconds ? best : 0.0;
}

}  // namespace detail

/// Decides the convention of `raw` (the field's values as stored, one per point) and rewrites
/// them as seconds relative to `stamp_s`; clears them when the field is all zero. Returns false
/// (leaving `info.reference` none) when the values fit no convention: the caller reports it.
inline bool resolve_point_times(std::vector<double>& raw, double stamp_s, PointTimeInfo& info) {
  info.reference = TimeReference::none;
  if (raw.empty()) return true;
  const auto [lo_it, hi_it] = std::minmax_element(raw.begin(), raw.end());
  const double lo = *lo_it, hi = *hi_it;
  if (!std::isfinite(lo) || !std::isfinite(hi)) return false;
  if (lo == 0.0 && hi == 0.0) {
    raw.clear();
    return true;
  }
  if (const double unit = detail::absolute_unit(lo, hi, stamp_s); unit != 0.0) {
    info.seconds_per_unit = unit;
    info.reference = TimeReference::absolute;
    // Subtract in the stored unit first: absolute nanoseconds keep their precision.
    const double stamp_units = stamp_s / unit;
    for (double& t : raw) t = (t - stamp_units) * unit;
    return true;
  }
  const double unit = io::is_integer(info.type) ? 1e-9 : 1.0;
  if ((hi - lo) * unit >= kMaxSweepSeconds || std::abs(lo * unit) >= kMaxSweepSeconds) return false;
  info.seconds_per_unit = unit;
  info.reference = TimeReference::relative;
  for (double& t : raw) t *= unit;
  return true;
}

}  // namespace ulc::bags
