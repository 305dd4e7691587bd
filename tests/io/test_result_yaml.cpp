// The YAML result: it parses back with yaml-cpp, and every form of the extrinsic it prints must
// rebuild the same transform.
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/result_yaml.hpp"

namespace {

/// The numbers of a text such as "0.31 -1.2 0.05" or "--x 0.31 --y -1.2" (words skipped).
std::vector<double> numbers(std::string s) {
  for (char& c : s)
    if (c == '"') c = ' ';
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

std::vector<double> list(const YAML::Node& node) {
  return node.as<std::vector<double>>();
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
  r.reason = "a \"quoted\" word: with a colon";
  r.time_offset_s = 0.0125;
  r.T_base_target = from_xyz_rpy(0.31, -1.2, 0.05, 0.4, -1.1, 2.9);
  return r;
}

}  // namespace

TEST_CASE("YAML result: matrix, quaternions, rpy, ROS and URDF forms all give the transform") {
  const ulc::io::PairResult r = example();
  const std::string text = ulc::io::results_to_yaml({r});
  const YAML::Node yaml = YAML::Load(text);
  REQUIRE(yaml["results"].size() == 1);
  const YAML::Node e = yaml["results"][0];
  const Eigen::Matrix4d M = r.T_base_target.matrix();

  REQUIRE(e["T_base_target"].size() == 4);
  for (int i = 0; i < 4; ++i) {
    const auto row = list(e["T_base_target"][i]);
    REQUIRE(row.size() == 4);
    for (int j = 0; j < 4; ++j) CHECK(row[j] == Approx(M(i, j)).margin(1e-8));
  }
  // The matrix rows read as rows in the text too.
  CHECK(text.find("    T_base_target:\n      - [") != std::string::npos);

  const auto wxyz = list(e["rotation_quat_wxyz"]);
  const auto xyzw = list(e["rotation_quat_xyzw"]);
  REQUIRE(wxyz.size() == 4);
  REQUIRE(xyzw.size() == 4);
  const Eigen::Quaterniond q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  CHECK(ulc::rotation_error_rad(q.toRotationMatrix(), r.T_base_target.linear()) < 1e-7);
  CHECK(xyzw[3] == wxyz[0]);
  CHECK(xyzw[0] == wxyz[1]);
  const auto rpy = list(e["rpy_rad"]);
  const auto rpy_deg = list(e["rpy_deg"]);
  const auto t = list(e["translation_m"]);
  REQUIRE(rpy.size() == 3);
  REQUIRE(t.size() == 3);
  CHECK(from_xyz_rpy(t[0], t[1], t[2], rpy[0], rpy[1], rpy[2]).isApprox(r.T_base_target, 1e-7));
  CHECK(rpy_deg.at(2) == Approx(rpy[2] * 180.0 / 3.14159265358979323846));

  // ROS 1: x y z yaw pitch roll parent child.
  const std::string ros1 = e["static_transform_publisher"].as<std::string>();
  const auto s = numbers(ros1);
  REQUIRE(s.size() == 6);
  CHECK(from_xyz_rpy(s[0], s[1], s[2], s[5], s[4], s[3]).isApprox(r.T_base_target, 1e-7));
  CHECK(ros1.size() > 9);
  CHECK(ros1.substr(ros1.size() - 9) == " top left");

  // ROS 2: named arguments.
  const auto s2 = numbers(e["ros2_static_transform_publisher"].as<std::string>());
  REQUIRE(s2.size() == 6);
  CHECK(from_xyz_rpy(s2[0], s2[1], s2[2], s2[3], s2[4], s2[5]).isApprox(r.T_base_target, 1e-7));

  // URDF: <origin xyz="..." rpy="..."/> with parent = base, child = target.
  const std::string urdf = e["urdf_joint"].as<std::string>();
  const auto origin = urdf.find("<origin xyz=\"");
  REQUIRE(origin != std::string::npos);
  const auto u = numbers(urdf.substr(origin + 13, urdf.find("/>", origin) - origin - 13));
  REQUIRE(u.size() == 6);
  CHECK(from_xyz_rpy(u[0], u[1], u[2], u[3], u[4], u[5]).isApprox(r.T_base_target, 1e-7));
  CHECK(urdf.find("<parent link=\"top\"/>") != std::string::npos);
  CHECK(urdf.find("<child link=\"left\"/>") != std::string::npos);

  CHECK(e["reason"].as<std::string>() == r.reason);
  CHECK(e["time_offset_s"].as<double>() == 0.0125);
  CHECK(e["success"].as<bool>());
  CHECK(e["base"].as<std::string>() == "top");
  CHECK(e["status"].as<std::string>() == "ok");
}

TEST_CASE("YAML result: one entry per target, a missing time offset is null") {
  ulc::io::PairResult a = example(), b = example();
  b.target = "right";
  b.time_offset_s.reset();
  b.success = false;
  const YAML::Node yaml = YAML::Load(ulc::io::results_to_yaml({a, b}));
  REQUIRE(yaml["results"].size() == 2);
  CHECK(yaml["results"][1]["target"].as<std::string>() == "right");
  CHECK(yaml["results"][1]["time_offset_s"].IsNull());
  CHECK_FALSE(yaml["results"][1]["success"].as<bool>());
  CHECK_FALSE(yaml["results"][0]["via"].IsDefined());
}

TEST_CASE("YAML result: non-finite numbers are YAML's .nan and .inf") {
  ulc::io::PairResult r = example();
  r.time_offset_s = std::numeric_limits<double>::quiet_NaN();
  r.T_base_target.translation().x() = std::numeric_limits<double>::infinity();
  const std::string text = ulc::io::results_to_yaml({r});
  CHECK(text.find("nan,") == std::string::npos);  // no bare nan: not YAML
  CHECK(text.find("time_offset_s: .nan") != std::string::npos);
  const YAML::Node e = YAML::Load(text)["results"][0];
  CHECK(std::isnan(e["time_offset_s"].as<double>()));
  CHECK(list(e["translation_m"]).at(0) == std::numeric_limits<double>::infinity());
  CHECK(list(e["T_base_target"][0]).at(3) == std::numeric_limits<double>::infinity());
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
  const std::string text = ulc::io::results_to_yaml({a, b}, {closed, open});
  const YAML::Node yaml = YAML::Load(text);
  // The route only on the routed entry.
  CHECK_FALSE(yaml["results"][0]["via"].IsDefined());
  CHECK(yaml["results"][1]["via"].as<std::string>() == "left");
  CHECK(yaml["results"][1]["direct_status"].as<std::string>() == "jeep_failed");
  CHECK(yaml["results"][1]["direct_reason"].as<std::string>() == "JEEP: rejected");
  const YAML::Node cycles = yaml["cycles"];
  REQUIRE(cycles.size() == 2);
  CHECK(cycles[0]["lidars"].as<std::vector<std::string>>() ==
        std::vector<std::string>{"top", "left", "right"});
  CHECK(cycles[0]["status"].as<std::string>() == "ok");
  CHECK(cycles[0]["rotation_deg"].as<double>() == 0.125);
  CHECK(cycles[0]["translation_m"].as<double>() == 0.0075);
  CHECK(cycles[1]["rotation_deg"].IsNull());
  CHECK(cycles[1]["lidars"][2].as<std::string>() == "back");
  // The cycles come after the results, with their comment; without cycles there is no key.
  CHECK(text.find("# cycle closure") < text.find("\ncycles:\n"));
  CHECK(text.find("\ncycles:\n") > text.find("target: \"right\""));
  CHECK_FALSE(YAML::Load(ulc::io::results_to_yaml({a}))["cycles"].IsDefined());
}

TEST_CASE("YAML result: an unwritable path throws an IoError naming it") {
  CHECK_THROWS_WITH(ulc::io::write_result_yaml("/nonexistent_dir/x.yaml", {example()}),
                    Catch::Contains("/nonexistent_dir/x.yaml"));
}
