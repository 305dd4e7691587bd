// Which fields of a file become x, y, z, intensity and the per-point time.
//
// Shared by PCD (FIELDS) and PLY (vertex properties):
//   x, y, z      required, COUNT 1, any numeric type.
//   intensity    the field named `intensity` (COUNT 1), when present.
//   time         the first present (COUNT 1) of `t`, `time`, `timestamp`, `offset_time`, in that
//                order of preference. Floating-point time fields are seconds. Integer time fields
//                are nanoseconds and are scaled by 1e-9: that is what drivers store in integers
//                (Livox `offset_time` uint32 ns since the frame start, Ouster `t` uint32 ns).
//                Values are kept as read otherwise: absolute Unix times stay absolute here; the
//                sequence layer makes them relative to the frame.
// Every other field is skipped, whatever its type or COUNT.
#pragma once

#include <string>
#include <vector>

#include "ulc/io/io_error.hpp"
#include "ulc/io/read_stats.hpp"
#include "ulc/io/scalar_type.hpp"

namespace ulc::io {

struct FieldDesc {
  std::string name;
  ScalarType type = ScalarType::float32;
  std::size_t count = 1;
};

struct FieldRoles {
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t x = kNone, y = kNone, z = kNone;
  std::size_t intensity = kNone;
  std::size_t time = kNone;
  double time_scale = 1.0;  ///< seconds per stored unit of the time field

  bool has_intensity() const { return intensity != kNone; }
  bool has_time() const { return time != kNone; }
};

inline constexpr const char* kTimeFieldNames[] = {"t", "time", "timestamp", "offset_time"};

/// Picks the roles; throws IoError(file, position, ...) when x, y or z is missing or not COUNT 1.
inline FieldRoles assign_field_roles(const std::vector<FieldDesc>& fields, const std::string& file,
                                     const std::string& position) {
  auto find = [&](const std::string& name) {
    for (std::size_t i = 0; i < fields.size(); ++i)
      if (fields[i].name == name) return i;
    return FieldRoles::kNone;
  };
  FieldRoles roles;
  std::size_t* axes[3] = {&roles.x, &roles.y, &roles.z};
  const char* axis_names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    *axes[a] = find(axis_names[a]);
    if (*axes[a] == FieldRoles::kNone)
      throw IoError(file, position,
                    std::string("no field named ") + axis_names[a] + " (x, y and z are required)");
    if (fields[*axes[a]].count != 1)
      throw IoError(file, position,
                    std::string("field ") + axis_names[a] + " has COUNT " +
                        std::to_string(fields[*axes[a]].count) + ", expected 1");
  }
  const std::size_t intensity = find("intensity");
  if (intensity != FieldRoles::kNone && fields[intensity].count == 1) roles.intensity = intensity;
  for (const char* name : kTimeFieldNames) {
    const std::size_t t = find(name);
    if (t == FieldRoles::kNone || fields[t].count != 1) continue;
    roles.time = t;
    roles.time_scale = is_integer(fields[t].type) ? 1e-9 : 1.0;
    break;
  }
  return roles;
}

/// Records the field list and the chosen roles in stats.
inline void describe_fields(const std::vector<FieldDesc>& fields, const FieldRoles& roles,
                            ReadStats& stats) {
  stats.fields.clear();
  for (const FieldDesc& f : fields) stats.fields.push_back(f.name);
  stats.intensity_field = roles.has_intensity() ? fields[roles.intensity].name : std::string();
  stats.time_field = roles.has_time() ? fields[roles.time].name : std::string();
  stats.time_scale = roles.time_scale;
}

}  // namespace ulc::io
