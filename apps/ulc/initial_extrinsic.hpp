// `--initial` of `ulc calibrate`: "x y z roll pitch yaw" (metres, degrees, R = Rz(yaw) Ry(pitch)
// Rx(roll), the ROS convention) or a result file (docs/design.md, "The command line"). From a
// result file, the entry for the same base and target is used when there is one, else the first
// entry.
#pragma once

#include <Eigen/Geometry>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "ulc/core/lie.hpp"
#include "ulc/io/result_file.hpp"
#include "usage_error.hpp"

namespace ulc::app {

/// Whether `text` names a result file rather than six numbers.
inline bool initial_is_file(const std::string& text) {
  std::error_code ec;
  const std::filesystem::path p(text);
  return p.extension() == ".json" || std::filesystem::is_regular_file(p, ec);
}

/// Six numbers separated by spaces (or commas), else UsageError naming the option.
inline Eigen::Isometry3d parse_initial_numbers(const std::string& text) {
  std::string spaced = text;
  for (char& c : spaced)
    if (c == ',') c = ' ';
  std::istringstream in(spaced);
  std::vector<double> v;
  for (std::string token; in >> token;) {
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(token.c_str(), &end);
    if (*end != '\0' || errno == ERANGE || !std::isfinite(x)) {
      v.clear();
      break;
    }
    v.push_back(x);
  }
  if (v.size() != 6)
    throw UsageError(
        "calibrate: option '--initial' expects \"x y z roll pitch yaw\" (metres, degrees) or a "
        "result file (.json), got '" +
        text + "'");
  constexpr double kRad = 3.14159265358979323846 / 180.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ulc::rotation_from_rpy(v[3] * kRad, v[4] * kRad, v[5] * kRad);
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return T;
}

/// The initial T_base_target for the pair (base, target). Throws UsageError or io::IoError.
inline Eigen::Isometry3d parse_initial(const std::string& text, const std::string& base,
                                       const std::string& target) {
  if (!initial_is_file(text)) return parse_initial_numbers(text);
  const std::vector<io::PairResult> results = io::read_result_file(text);
  if (results.empty())
    throw UsageError("calibrate: --initial " + text + ": the result file has no entry");
  for (const auto& r : results)
    if (r.base == base && r.target == target) return r.T_base_target;
  return results.front().T_base_target;
}

}  // namespace ulc::app
