// Which fields the writers emit for a cloud, shared by PCD and PLY.
//
// Always x y z as float32; `intensity` float32 when ulc::traits::has_intensity(cloud); `t` when
// ulc::traits::has_time(cloud): float32 seconds, except when some time is absolute (magnitude
// above kAbsoluteTimeThreshold, i.e. Unix seconds), where float32 would round to minutes, so `t`
// is then written as float64. Readers accept both. The detail helpers below turn a cloud into
// those values, so the PCD and PLY writers share one definition.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "ulc/core/point_traits.hpp"
#include "ulc/io/endian.hpp"
#include "ulc/io/number_format.hpp"

namespace ulc::io {

/// Seconds. A per-point time above this is an absolute (Unix) time, not one relative to its frame.
constexpr double kAbsoluteTimeThreshold = 1e6;

struct WrittenFields {
  bool intensity = false;
  bool time = false;
  bool time_is_double = false;
};

template <typename Cloud>
WrittenFields written_fields(const Cloud& cloud) {
  WrittenFields w;
  w.intensity = traits::has_intensity(cloud);
  w.time = traits::has_time(cloud);
  if (w.time) {
    const std::size_t n = traits::size(cloud);
    for (std::size_t i = 0; i < n && !w.time_is_double; ++i)
      w.time_is_double = std::abs(traits::time(cloud, i)) > kAbsoluteTimeThreshold;
  }
  return w;
}

namespace detail {

enum class OutField { x, y, z, intensity, time };

struct OutFieldSpec {
  OutField field;
  const char* name;
  std::size_t size;  ///< 4 (float32) or 8 (float64)
};

inline std::vector<OutFieldSpec> out_field_specs(const WrittenFields& w) {
  std::vector<OutFieldSpec> specs = {
      {OutField::x, "x", 4}, {OutField::y, "y", 4}, {OutField::z, "z", 4}};
  if (w.intensity) specs.push_back({OutField::intensity, "intensity", 4});
  if (w.time) specs.push_back({OutField::time, "t", w.time_is_double ? std::size_t{8} : 4});
  return specs;
}

/// Value of one output field of point i, as double (exact for the float32 it came from).
template <typename Cloud>
double out_value(const Cloud& cloud, std::size_t i, OutField f) {
  switch (f) {
    case OutField::x:
    case OutField::y:
    case OutField::z:
      return static_cast<double>(traits::point(cloud, i)[static_cast<int>(f)]);
    case OutField::intensity:
      return static_cast<double>(traits::intensity(cloud, i));
    case OutField::time:
      return traits::time(cloud, i);
  }
  return 0.0;
}

/// Stores a field value as float32 or float64 with the given byte order.
inline void put_value(unsigned char* p, double v, std::size_t size, Endian order) {
  if (size == 8)
    store<double>(p, v, order);
  else
    store<float>(p, static_cast<float>(v), order);
}

inline void append_value(std::string& text, double v, std::size_t size) {
  if (size == 8)
    append_number(text, v);
  else
    append_number(text, static_cast<float>(v));
}

/// The ascii body shared by PCD and PLY: one line per point, fields separated by spaces.
template <typename Cloud>
std::string ascii_rows(const Cloud& cloud, const std::vector<OutFieldSpec>& specs) {
  std::string text;
  const std::size_t n = traits::size(cloud);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < specs.size(); ++k) {
      if (k) text += ' ';
      append_value(text, out_value(cloud, i, specs[k].field), specs[k].size);
    }
    text += '\n';
  }
  return text;
}

}  // namespace detail

}  // namespace ulc::io
