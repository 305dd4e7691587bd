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
// Numbers are written with 9 significant digits (sub-micrometre, sub-microradian).
// A routed entry (result_file.hpp) adds `via` and `direct_status` / `direct_reason`; a rig's
// cycle closures follow the results as a top-level `cycles` list, the JSON file's fields.
#pragma once

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ulc/core/lie.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/result_file.hpp"

namespace ulc::io {

namespace yaml_detail {

inline std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", v);
  return buffer;
}

/// A double-quoted YAML scalar (also valid inside a shell command line for plain names).
inline std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

template <class V>
std::string list(const V& v) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) out += (i ? ", " : "") + num(v[i]);
  return out + "]";
}

}  // namespace yaml_detail

/// The YAML text of `results` and, when there are any, `cycles`.
inline std::string results_to_yaml(const std::vector<PairResult>& results,
                                   const std::vector<CycleResult>& cycles = {}) {
  using namespace yaml_detail;
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  std::ostringstream y;
  y << "# ULC calibration result: p_base = T_base_target * p_target\n";
  y << "# time offset convention: t_base_clock = t_target_clock + time_offset_s\n";
  y << "results:\n";
  for (const PairResult& r : results) {
    const Eigen::Isometry3d& T = r.T_base_target;
    const Eigen::Vector3d t = T.translation();
    const Eigen::Vector3d rpy = ulc::rpy_from_rotation(Eigen::Matrix3d(T.linear()));
    const Eigen::Quaterniond q(T.linear());
    y << "  - base: " << quoted(r.base) << "\n";
    y << "    target: " << quoted(r.target) << "\n";
    y << "    success: " << (r.success ? "true" : "false") << "\n";
    y << "    status: " << quoted(r.status) << "\n";
    y << "    reason: " << quoted(r.reason) << "\n";
    if (!r.via.empty()) {
      y << "    via: " << quoted(r.via) << "\n";
      y << "    direct_status: " << quoted(r.direct_status) << "\n";
      y << "    direct_reason: " << quoted(r.direct_reason) << "\n";
    }
    y << "    time_offset_s: " << (r.time_offset_s ? num(*r.time_offset_s) : "null") << "\n";
    y << "    T_base_target:\n";
    for (int i = 0; i < 4; ++i)
      y << "      - " << list(Eigen::Vector4d(T.matrix().row(i).transpose())) << "\n";
    y << "    translation_m: " << list(t) << "\n";
    y << "    rotation_quat_wxyz: " << list(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z())) << "\n";
    y << "    rotation_quat_xyzw: " << list(Eigen::Vector4d(q.x(), q.y(), q.z(), q.w())) << "\n";
    y << "    rpy_deg: " << list(Eigen::Vector3d(rpy * kDeg)) << "\n";
    y << "    rpy_rad: " << list(rpy) << "\n";
    y << "    static_transform_publisher: "
      << quoted(num(t.x()) + " " + num(t.y()) + " " + num(t.z()) + " " + num(rpy.z()) + " " +
                num(rpy.y()) + " " + num(rpy.x()) + " " + r.base + " " + r.target)
      << "\n";
    y << "    ros2_static_transform_publisher: "
      << quoted("--x " + num(t.x()) + " --y " + num(t.y()) + " --z " + num(t.z()) + " --roll " +
                num(rpy.x()) + " --pitch " + num(rpy.y()) + " --yaw " + num(rpy.z()) +
                " --frame-id " + r.base + " --child-frame-id " + r.target)
      << "\n";
    y << "    urdf_joint: |\n";
    y << "      <joint name=\"" << r.base << "_to_" << r.target << "\" type=\"fixed\">\n";
    y << "        <parent link=\"" << r.base << "\"/>\n";
    y << "        <child link=\"" << r.target << "\"/>\n";
    y << "        <origin xyz=\"" << num(t.x()) << " " << num(t.y()) << " " << num(t.z())
      << "\" rpy=\"" << num(rpy.x()) << " " << num(rpy.y()) << " " << num(rpy.z()) << "\"/>\n";
    y << "      </joint>\n";
  }
  if (!cycles.empty()) {
    y << "# cycle closure: T_base_i * T_i_j * T_base_j^-1, null when i -> j did not calibrate\n";
    y << "cycles:\n";
    for (const CycleResult& c : cycles) {
      y << "  - lidars: [";
      for (std::size_t k = 0; k < c.lidars.size(); ++k) y << (k ? ", " : "") << quoted(c.lidars[k]);
      y << "]\n";
      y << "    status: " << quoted(c.status) << "\n";
      y << "    reason: " << quoted(c.reason) << "\n";
      y << "    rotation_deg: " << (c.rotation_deg ? num(*c.rotation_deg) : "null") << "\n";
      y << "    translation_m: " << (c.translation_m ? num(*c.translation_m) : "null") << "\n";
    }
  }
  return y.str();
}

/// Writes results_to_yaml to `path`; throws IoError when the file cannot be written.
inline void write_result_yaml(const std::string& path, const std::vector<PairResult>& results,
                              const std::vector<CycleResult>& cycles = {}) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw IoError(path, "", "cannot open for writing");
  out << results_to_yaml(results, cycles);
  if (!out.flush()) throw IoError(path, "", "write failed");
}

}  // namespace ulc::io
