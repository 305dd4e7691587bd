#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>

#include "test_paths.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/json_file.hpp"
#include "ulc/io/result_file.hpp"

using ulc::io::IoError;
using ulc::io::Json;
using ulc::io::parse_json;

namespace {

std::string error_of(const std::string& text) {
  try {
    parse_json(text, "doc.json");
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// The JSON itself is nlohmann::json's; these tests cover what is ours: the errors (file, line,
// column), the layout of written files, and the readers of the result file and ground truth.

TEST_CASE("malformed JSON is an IoError naming the file, line and column", "[json]") {
  CHECK_THAT(error_of(""), Catch::Contains("doc.json: line 1, column 1: "));
  CHECK_THAT(error_of("{\n  \"a\": 1,\n  \"b\" 2\n}"),
             Catch::Contains("doc.json: line 3, column ") && Catch::Contains("expected ':'"));
  CHECK_THAT(error_of("[1, 2"),
             Catch::Contains("doc.json: line 1") && Catch::Contains("unexpected end of input"));
  CHECK_THAT(error_of("{\"a\": tru}"), Catch::Contains("doc.json: line 1"));
  CHECK_THAT(error_of("1 2"), Catch::Contains("doc.json: line 1"));
  CHECK_THAT(error_of("1e999"), Catch::Contains("doc.json: ") && Catch::Contains("1e999"));
  CHECK_THAT(error_of(std::string(100000, '[')), Catch::Contains("doc.json: nesting deeper"));
  CHECK_NOTHROW(parse_json(std::string(200, '[') + std::string(200, ']')));
}

TEST_CASE("reading a JSON file names it when it is missing or malformed", "[json]") {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string missing = (dir / "ulc_test_json_missing.json").string();
  CHECK_THROWS_WITH(ulc::io::read_json_file(missing),
                    Catch::Contains(missing) && Catch::Contains("cannot open file"));
  const std::string broken = (dir / "ulc_test_json_broken.json").string();
  { std::ofstream(broken) << "{\"results\": ["; }
  CHECK_THROWS_WITH(ulc::io::read_result_file(broken),
                    Catch::Contains(broken + ": line 1, column 14: "));
  CHECK_THROWS_WITH(ulc::io::read_ground_truth(broken), Catch::Contains(broken + ": line 1"));
  std::filesystem::remove(broken);
}

TEST_CASE("written JSON keeps key order, rows of numbers on one line, and round trips", "[json]") {
  Json doc = Json::object();
  doc["zeta"] = "quote \" backslash \\ newline \n unicode \xC3\xA9";
  doc["matrix"] = ulc::io::matrix_to_json(Eigen::Matrix2d(Eigen::Matrix2d::Identity() * 0.1));
  doc["empty"] = Json::array();
  doc["nothing"] = Json::object();
  doc["names"] = {"a", "b"};
  doc["n"] = 42;
  const std::string text = ulc::io::dump_json(doc);
  CHECK(text ==
        "{\n"
        " \"zeta\": \"quote \\\" backslash \\\\ newline \\n unicode \xC3\xA9\",\n"
        " \"matrix\": [\n"
        "  [0.1, 0.0],\n"
        "  [0.0, 0.1]\n"
        " ],\n"
        " \"empty\": [],\n"
        " \"nothing\": {},\n"
        " \"names\": [\"a\", \"b\"],\n"
        " \"n\": 42\n"
        "}");
  const Json back = parse_json(text);
  CHECK(back == doc);
  CHECK(back.begin().key() == "zeta");  // insertion order kept

  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(-1e6, 1e6);
  Json numbers = Json::array();
  for (int i = 0; i < 200; ++i) numbers.push_back(uni(rng) * std::pow(10.0, (i % 21) - 10));
  CHECK(parse_json(ulc::io::dump_json(numbers)) == numbers);  // bit for bit
}

TEST_CASE("non-finite numbers are written as null, bad UTF-8 replaced", "[json]") {
  Json arr = Json::array();
  arr.push_back(std::numeric_limits<double>::quiet_NaN());
  arr.push_back(std::numeric_limits<double>::infinity());
  arr.push_back("bad \xFF byte");
  CHECK(ulc::io::dump_json(arr) == "[null, null, \"bad \xEF\xBF\xBD byte\"]");
}

TEST_CASE("ground truth round trips through ground_truth.json", "[json][ground_truth]") {
  ulc::io::GroundTruth gt;
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
  a.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  a.translation() = Eigen::Vector3d(1.25, -0.5, 2.0);
  gt.lidars.push_back({"top", "HDL-64E", Eigen::Isometry3d::Identity()});
  gt.lidars.push_back({"left", "VLP-16", a});
  gt.pairs.push_back({"top", "left", a, 0.05});
  gt.pairs.push_back({"top", "right", a.inverse(), std::nullopt});

  const auto path = std::filesystem::temp_directory_path() / "ulc_test_gt.json";
  ulc::io::write_ground_truth(path.string(), gt);
  const auto back = ulc::io::read_ground_truth(path.string());
  std::filesystem::remove(path);

  REQUIRE(back.lidars.size() == 2);
  CHECK(back.find_lidar("left")->model == "VLP-16");
  CHECK(back.find_lidar("left")->T_vehicle_lidar.isApprox(a, 1e-15));
  REQUIRE(back.pairs.size() == 2);
  CHECK(back.find_pair("top", "left")->time_offset_s == Approx(0.05));
  CHECK_FALSE(back.find_pair("top", "right")->time_offset_s.has_value());
  CHECK(back.find_pair("top", "right")->T_base_target.isApprox(a.inverse(), 1e-12));
}

TEST_CASE("ground truth rejects transforms that are not rigid", "[json][ground_truth]") {
  const std::string bad_rotation =
      R"({"pairs": [{"base": "a", "target": "b", "T_base_target":
          [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}]})";
  CHECK_THROWS_WITH(ulc::io::ground_truth_from_json(parse_json(bad_rotation), "gt.json"),
                    Catch::Contains("gt.json") && Catch::Contains("not a rotation"));
  const std::string short_row =
      R"({"pairs": [{"base": "a", "target": "b", "T_base_target": [[1,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}]})";
  CHECK_THROWS_WITH(ulc::io::ground_truth_from_json(parse_json(short_row), "gt.json"),
                    Catch::Contains("row 0"));
  CHECK_THROWS_WITH(ulc::io::ground_truth_from_json(parse_json("{}"), "gt.json"),
                    Catch::Contains("pairs"));
}

TEST_CASE("the real croon_0003 ground truth parses", "[json][ground_truth][real]") {
  const auto dir = ulc_test::croon_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/real/croon_0003 not found");
  const auto gt = ulc::io::read_ground_truth((dir / "ground_truth.json").string());
  REQUIRE(gt.pairs.size() == 2);
  const auto* left = gt.find_pair("top", "left");
  REQUIRE(left != nullptr);
  CHECK_FALSE(left->time_offset_s.has_value());  // null in the file
  CHECK(left->T_base_target.translation().y() == Approx(0.560820537));
  // The side units are tilted about 45 degrees and yawed about 90 degrees.
  const double angle = Eigen::AngleAxisd(left->T_base_target.linear()).angle();
  CHECK(angle > 1.3);
  CHECK(angle < 2.2);
}

TEST_CASE("result files round trip and spell the transform consistently", "[json][result]") {
  ulc::io::PairResult r;
  r.base = "top";
  r.target = "left";
  r.success = true;
  r.status = "ok";
  r.T_base_target.linear() = ulc::rotation_from_rpy(0.1, -0.2, 1.3);
  r.T_base_target.translation() = Eigen::Vector3d(0.5, -1.0, 0.25);
  r.time_offset_s = 0.05;
  r.covariance_6x6 = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;
  r.stages["terra"]["rotations_evaluated"] = 1234;
  r.stages["terra"]["rpy_deg"] = {0.5, 1.0, 2.0};
  r.timing_s["total"] = 0.25;

  const Json doc = ulc::io::results_to_json({r});
  const Json& e = doc.at("results")[0];
  const double kDeg = 180.0 / 3.14159265358979323846;
  CHECK(e.at("rpy_deg")[0].get<double>() == Approx(0.1 * kDeg));
  CHECK(e.at("rpy_deg")[1].get<double>() == Approx(-0.2 * kDeg));
  CHECK(e.at("rpy_deg")[2].get<double>() == Approx(1.3 * kDeg));
  const Eigen::Quaterniond q(
      e.at("rotation_quat_wxyz")[0].get<double>(), e.at("rotation_quat_wxyz")[1].get<double>(),
      e.at("rotation_quat_wxyz")[2].get<double>(), e.at("rotation_quat_wxyz")[3].get<double>());
  CHECK(q.toRotationMatrix().isApprox(r.T_base_target.linear(), 1e-12));
  CHECK(e.at("translation_m")[2].get<double>() == 0.25);

  const auto back = ulc::io::results_from_json(parse_json(ulc::io::dump_json(doc)), "result.json");
  REQUIRE(back.size() == 1);
  CHECK(back[0].success);
  CHECK(back[0].T_base_target.isApprox(r.T_base_target, 1e-14));
  CHECK(*back[0].time_offset_s == 0.05);
  CHECK(back[0].covariance_6x6->isApprox(*r.covariance_6x6));
  CHECK(back[0].stages == r.stages);
  CHECK(back[0].timing_s == r.timing_s);

  CHECK_THROWS_WITH(ulc::io::results_from_json(parse_json("{\"pairs\": []}"), "x.json"),
                    Catch::Contains("x.json") && Catch::Contains("results"));
}

TEST_CASE("result files: keys and types a reader relies on", "[json][result]") {
  ulc::io::PairResult r;
  r.base = "top";
  r.target = "left";
  r.status = "terra_failed";
  ulc::io::CycleResult c;
  c.lidars = {"top", "left", "right"};
  c.rotation_deg = 0.5;
  const Json doc = ulc::io::results_to_json({r}, {c});
  const Json& e = doc.at("results")[0];
  std::vector<std::string> keys;
  for (auto it = e.begin(); it != e.end(); ++it) keys.push_back(it.key());
  CHECK(keys == std::vector<std::string>{"base", "target", "success", "status", "reason",
                                         "T_base_target", "translation_m", "rotation_quat_wxyz",
                                         "rpy_deg", "time_offset_s", "covariance_6x6",
                                         "observability", "unobservable", "stages", "timing_s"});
  CHECK(e.at("time_offset_s").is_null());
  CHECK(e.at("unobservable").is_array());
  CHECK(e.at("covariance_6x6").is_null());
  CHECK(doc.at("cycles")[0].at("translation_m").is_null());
  const auto cycles = ulc::io::cycles_from_json(parse_json(ulc::io::dump_json(doc)), "r.json");
  REQUIRE(cycles.size() == 1);
  CHECK(*cycles[0].rotation_deg == 0.5);
  CHECK_FALSE(cycles[0].translation_m.has_value());

  // Wrong types name the file and the field.
  const std::string large_offset =
      R"({"results": [{"base": "a", "target": "b", "time_offset_s": 1e308,
          "T_base_target": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}]})";
  CHECK_NOTHROW(ulc::io::results_from_json(parse_json(large_offset), "r.json"));
  const std::string not_a_matrix =
      R"({"results": [{"base": "a", "target": "b", "T_base_target": "identity"}]})";
  CHECK_THROWS_WITH(ulc::io::results_from_json(parse_json(not_a_matrix), "r.json"),
                    Catch::Contains("r.json: results[0].T_base_target: "));
  CHECK_THROWS_WITH(
      ulc::io::cycles_from_json(parse_json(R"({"cycles": [{"lidars": [1]}]})"), "r.json"),
      Catch::Contains("r.json: cycles[0].lidars: expected names"));
}
