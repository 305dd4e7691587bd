// The result file as YAML (`ulc calibrate --format yaml`): per target, the extrinsic in every
// form a robotics engineer pastes somewhere else.
//
// Conventions: T_base_target maps target points into the base frame (docs/design.md). In ROS terms
// the base LiDAR is the parent frame and the target the child, so
//   - static_transform_publisher (ROS 1 tf / tf2_ros) takes "x y z yaw pitch roll parent child"
//     with angles in radians;
//   - the ROS 2 form takes named arguments (--x ... --yaw ... --frame-id --child-frame-id);
//   - a URDF joint's <origin xyz rpy> uses fixed-axis roll, pitch, yaw in radians, i.e.
//     R = Rz(yaw) Ry(pitch) Rx(roll), the convention of ulc::rpy_from_rotation.
// Quaternions are given as w x y z (the JSON file's order) and x y z w (ROS message order).
// Numbers are written with 9 significant digits (sub-micrometre, sub-microradian); a non-finite
// number as YAML's .nan / .inf / -.inf, a missing one as null.
// Written with yaml-cpp's emitter (Debian's libyaml-cpp-dev): component ulc::results.
// A routed entry (result_file.hpp) adds `via` and `direct_status` / `direct_reason`; a rig's
// cycle closures follow the results as a top-level `cycles` list, the JSON file's fields. A
// degenerate entry lists its free directions under `unobservable` (words, vector, share).
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "ulc/core/angles.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/io/file_bytes.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/result_file.hpp"

namespace ulc::io {

namespace yaml_detail {

/// A number inside a command line or a URDF attribute (the emitter writes the YAML numbers).
inline std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", v);
  return buffer;
}

/// `key: "value"`, double-quoted (also valid inside a shell command line for plain names).
inline void quoted(YAML::Emitter& y, const char* key, const std::string& value) {
  y << YAML::Key << key << YAML::Value << YAML::DoubleQuoted << value;
}

/// `key: number`, or `key: null` when there is none.
inline void number(YAML::Emitter& y, const char* key, const std::optional<double>& value) {
  y << YAML::Key << key << YAML::Value;
  if (value)
    y << *value;
  else
    y << YAML::Null;
}

/// `[a, b, c]`.
template <class V>
void row(YAML::Emitter& y, const V& v) {
  y << YAML::Flow << YAML::BeginSeq;
  for (Eigen::Index i = 0; i < v.size(); ++i) y << static_cast<double>(v[i]);
  y << YAML::EndSeq;
}

template <class V>
void row(YAML::Emitter& y, const char* key, const V& v) {
  y << YAML::Key << key << YAML::Value;
  row(y, v);
}

/// `unobservable:` the free directions (words and vector), written only when there are some.
inline void unobservable(YAML::Emitter& y, const std::vector<ulc::UnobservableDirection>& free) {
  if (free.empty()) return;
  y << YAML::Key << "unobservable" << YAML::Value << YAML::BeginSeq;
  for (const auto& d : free) {
    y << YAML::BeginMap;
    quoted(y, "words", d.words);
    row(y, "vector", d.vector);
    y << YAML::Key << "share" << YAML::Value << d.share;
    y << YAML::EndMap;
  }
  y << YAML::EndSeq;
}

inline void result(YAML::Emitter& y, const PairResult& r) {
  const Eigen::Isometry3d& T = r.T_base_target;
  const Eigen::Vector3d t = T.translation();
  const Eigen::Vector3d rpy = ulc::rpy_from_rotation(Eigen::Matrix3d(T.linear()));
  const Eigen::Quaterniond q(T.linear());
  y << YAML::BeginMap;
  quoted(y, "base", r.base);
  quoted(y, "target", r.target);
  y << YAML::Key << "success" << YAML::Value << r.success;
  quoted(y, "status", r.status);
  quoted(y, "reason", r.reason);
  if (!r.via.empty()) {
    quoted(y, "via", r.via);
    quoted(y, "direct_status", r.direct_status);
    quoted(y, "direct_reason", r.direct_reason);
  }
  number(y, "time_offset_s", r.time_offset_s);
  unobservable(y, r.unobservable);
  y << YAML::Key << "T_base_target" << YAML::Value << YAML::BeginSeq;
  for (int i = 0; i < 4; ++i) row(y, Eigen::Vector4d(T.matrix().row(i).transpose()));
  y << YAML::EndSeq;
  row(y, "translation_m", t);
  row(y, "rotation_quat_wxyz", Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
  row(y, "rotation_quat_xyzw", Eigen::Vector4d(q.x(), q.y(), q.z(), q.w()));
  row(y, "rpy_deg", Eigen::Vector3d(rpy * kDegPerRad));
  row(y, "rpy_rad", rpy);
  quoted(y, "static_transform_publisher",
         num(t.x()) + " " + num(t.y()) + " " + num(t.z()) + " " + num(rpy.z()) + " " +
             num(rpy.y()) + " " + num(rpy.x()) + " " + r.base + " " + r.target);
  quoted(y, "ros2_static_transform_publisher",
         "--x " + num(t.x()) + " --y " + num(t.y()) + " --z " + num(t.z()) + " --roll " +
             num(rpy.x()) + " --pitch " + num(rpy.y()) + " --yaw " + num(rpy.z()) + " --frame-id " +
             r.base + " --child-frame-id " + r.target);
  y << YAML::Key << "urdf_joint" << YAML::Value << YAML::Literal
    << "<joint name=\"" + r.base + "_to_" + r.target + "\" type=\"fixed\">\n" +
           "  <parent link=\"" + r.base + "\"/>\n" + "  <child link=\"" + r.target + "\"/>\n" +
           "  <origin xyz=\"" + num(t.x()) + " " + num(t.y()) + " " + num(t.z()) + "\" rpy=\"" +
           num(rpy.x()) + " " + num(rpy.y()) + " " + num(rpy.z()) + "\"/>\n" + "</joint>\n";
  y << YAML::EndMap;
}

inline void cycle(YAML::Emitter& y, const CycleResult& c) {
  y << YAML::BeginMap << YAML::Key << "lidars" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const std::string& name : c.lidars) y << YAML::DoubleQuoted << name;
  y << YAML::EndSeq;
  quoted(y, "status", c.status);
  quoted(y, "reason", c.reason);
  number(y, "rotation_deg", c.rotation_deg);
  number(y, "translation_m", c.translation_m);
  y << YAML::EndMap;
}

}  // namespace yaml_detail

/// The YAML text of `results` and, when there are any, `cycles`.
inline std::string results_to_yaml(const std::vector<PairResult>& results,
                                   const std::vector<CycleResult>& cycles = {}) {
  YAML::Emitter y;
  y.SetDoublePrecision(9);
  y.SetNullFormat(YAML::LowerNull);
  y << YAML::Comment("ULC calibration result: p_base = T_base_target * p_target") << YAML::Newline
    << YAML::Comment("time offset convention: t_base_clock = t_target_clock + time_offset_s")
    << YAML::Newline;
  y << YAML::BeginMap << YAML::Key << "results" << YAML::Value << YAML::BeginSeq;
  for (const PairResult& r : results) yaml_detail::result(y, r);
  y << YAML::EndSeq;
  if (!cycles.empty()) {
    y << YAML::Newline
      << YAML::Comment(
             "cycle closure: T_base_i * T_i_j * T_base_j^-1, null when i -> j did not calibrate");
    y << YAML::Key << "cycles" << YAML::Value << YAML::BeginSeq;
    for (const CycleResult& c : cycles) yaml_detail::cycle(y, c);
    y << YAML::EndSeq;
  }
  y << YAML::EndMap;
  if (!y.good()) throw IoError("<yaml>", "", "YAML emitter: " + y.GetLastError());
  return std::string(y.c_str()) + "\n";
}

/// Writes results_to_yaml to `path` atomically (atomic_file.hpp); throws IoError when the file
/// cannot be written.
inline void write_result_yaml(const std::string& path, const std::vector<PairResult>& results,
                              const std::vector<CycleResult>& cycles = {}) {
  write_file_text(path, results_to_yaml(results, cycles));
}

}  // namespace ulc::io
