// The YAML result: every form of the extrinsic it prints must rebuild the same transform.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <sstream>
#include <string>

#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/result_yaml.hpp"

namespace {

/// The text after `key: ` on the first line holding it (inside the first result).
std::string value_of(const std::string& yaml, const std::string& key) {
  const auto at = yaml.find(key + ": ");
  REQUIRE(at != std::string::npos);
  const auto begin = at + key.size() + 2;
  return yaml.substr(begin, yaml.find('\n', begin) - begin);
}

std::vector<double> numbers(std::string s) {
  for (char& c : s)
    if (c == '[' || c == ']' || c == ',' || c == '"') c = ' ';
  std::istringstream in(s);
  std::vector<double> out;
  std::string word;
  while (in >> word) {
    try {
      std::size_t used = 0;
      const double v = std::stod(word, &used);
      if (used == word.size()) out.push_back(v);
    } catch (const std::exception&) {
    }
  }
  return out;
}

Eigen::Isometry3d from_xyz_rpy(double x, double y, double z, double roll, double pitch,
                               double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ulc::rotation_from_rpy(roll, pitch, yaw);
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

ulc::io::PairResult example() {
  ulc::io::PairResult r;
  r.base = "top";
  r.target = "left";
  r.success = true;
  r.status = "ok";
  r.reason = "a \"quoted\" word";
  r.time_offset_s = 0.0125;
  r.T_base_target = from_xyz_rpy(0.31, -1.2, 0.05, 0.4, -1.1, 2.9);
  return r;
}

}  // namespace

TEST_CASE("YAML result: matrix, quaternions, rpy, ROS and URDF forms all give the transform") {
  const ulc::io::PairResult r = example();
  const std::string yaml = ulc::io::results_to_yaml({r});
  const Eigen::Matrix4d M = r.T_base_target.matrix();

  // The matrix rows follow "T_base_target:" as four "- [...]" lines.
  std::istringstream lines(yaml.substr(yaml.find("T_base_target:")));
  std::string line;
  std::getline(lines, line);
  for (int i = 0; i < 4; ++i) {
    std::getline(lines, line);
    const auto row = numbers(line);
    REQUIRE(row.size() == 4);
    for (int j = 0; j < 4; ++j) CHECK(row[j] == Approx(M(i, j)).margin(1e-8));
  }

  const auto wxyz = numbers(value_of(yaml, "rotation_quat_wxyz"));
  const auto xyzw = numbers(value_of(yaml, "rotation_quat_xyzw"));
  REQUIRE(wxyz.size() == 4);
  REQUIRE(xyzw.size() == 4);
  const Eigen::Quaterniond q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  CHECK(ulc::rotation_error_rad(q.toRotationMatrix(), r.T_base_target.linear()) < 1e-7);
  CHECK(xyzw[3] == wxyz[0]);
  CHECK(xyzw[0] == wxyz[1]);

  // ROS 1: x y z yaw pitch roll parent child.
  const std::string ros1 = value_of(yaml, "static_transform_publisher");
  const auto s = numbers(ros1);
  REQUIRE(s.size() == 6);
  CHECK(from_xyz_rpy(s[0], s[1], s[2], s[5], s[4], s[3]).isApprox(r.T_base_target, 1e-7));
  CHECK(ros1.find(" top left\"") != std::string::npos);

  // ROS 2: named arguments.
  const auto s2 = numbers(value_of(yaml, "ros2_static_transform_publisher"));
  REQUIRE(s2.size() == 6);
  CHECK(from_xyz_rpy(s2[0], s2[1], s2[2], s2[3], s2[4], s2[5]).isApprox(r.T_base_target, 1e-7));

  // URDF: <origin xyz="..." rpy="..."/> with parent = base, child = target.
  const auto origin = yaml.find("<origin xyz=\"");
  REQUIRE(origin != std::string::npos);
  const auto u = numbers(yaml.substr(origin, yaml.find("/>", origin) - origin));
  REQUIRE(u.size() == 6);
  CHECK(from_xyz_rpy(u[0], u[1], u[2], u[3], u[4], u[5]).isApprox(r.T_base_target, 1e-7));
  CHECK(yaml.find("<parent link=\"top\"/>") != std::string::npos);
  CHECK(yaml.find("<child link=\"left\"/>") != std::string::npos);

  CHECK(value_of(yaml, "reason") == "\"a \\\"quoted\\\" word\"");
  CHECK(numbers(value_of(yaml, "time_offset_s")).at(0) == Approx(0.0125));
  CHECK(value_of(yaml, "success") == "true");
}

TEST_CASE("YAML result: one entry per target, a missing time offset is null") {
  ulc::io::PairResult a = example(), b = example();
  b.target = "right";
  b.time_offset_s.reset();
  b.success = false;
  const std::string yaml = ulc::io::results_to_yaml({a, b});
  std::size_t entries = 0;
  for (std::size_t at = yaml.find("  - base: "); at != std::string::npos;
       at = yaml.find("  - base: ", at + 1))
    ++entries;
  CHECK(entries == 2);
  CHECK(yaml.find("time_offset_s: null") != std::string::npos);
  CHECK(yaml.find("success: false") != std::string::npos);
}

TEST_CASE("YAML result: a routed entry names its route, a rig's cycles follow the results") {
  ulc::io::PairResult a = example(), b = example();
  b.target = "right";
  b.via = "left";
  b.direct_status = "jeep_failed";
  b.direct_reason = "JEEP: rejected";
  ulc::io::CycleResult closed, open;
  closed.lidars = {"top", "left", "right"};
  closed.status = "ok";
  closed.rotation_deg = 0.125;
  closed.translation_m = 0.0075;
  open.lidars = {"top", "left", "back"};
  open.status = "terra_failed";
  const std::string yaml = ulc::io::results_to_yaml({a, b}, {closed, open});
  // The route only on the routed entry, after the results.
  CHECK(yaml.find("via: ") == yaml.find("    via: \"left\"\n") + 4);
  CHECK(yaml.find("via: ") > yaml.find("target: \"right\""));
  CHECK(yaml.find("direct_status: \"jeep_failed\"") != std::string::npos);
  CHECK(yaml.find("direct_reason: \"JEEP: rejected\"") != std::string::npos);
  const auto cycles = yaml.find("\ncycles:\n");
  REQUIRE(cycles != std::string::npos);
  CHECK(cycles > yaml.find("</joint>", yaml.find("target: \"right\"")));
  const std::string tail = yaml.substr(cycles);
  CHECK(tail.find("  - lidars: [\"top\", \"left\", \"right\"]\n    status: \"ok\"") !=
        std::string::npos);
  CHECK(numbers(value_of(tail, "rotation_deg")).at(0) == 0.125);
  CHECK(numbers(value_of(tail, "translation_m")).at(0) == 0.0075);
  CHECK(tail.find("rotation_deg: null") > tail.find("\"back\""));
  // Without cycles there is no cycles key (files of single pairs stay as they were).
  CHECK(ulc::io::results_to_yaml({a}).find("cycles") == std::string::npos);
}

TEST_CASE("YAML result: an unwritable path throws an IoError naming it") {
  CHECK_THROWS_AS(ulc::io::write_result_yaml("/nonexistent_dir/x.yaml", {example()}),
                  ulc::io::IoError);
}
