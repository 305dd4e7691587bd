#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <string>

#include "test_paths.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/json.hpp"
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

TEST_CASE("JSON numbers survive a round trip bit for bit", "[json]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(-1e6, 1e6);
  Json arr = Json::array();
  std::vector<double> values = {0.0, -0.0, 1.0, -1.5, 1e-300, 6.02214076e23, 0.1, 1.0 / 3.0};
  for (int i = 0; i < 200; ++i) values.push_back(uni(rng) * std::pow(10.0, (i % 21) - 10));
  for (double v : values) arr.push_back(v);
  const Json back = parse_json(arr.dump());
  REQUIRE(back.size() == values.size());
  for (std::size_t i = 0; i < values.size(); ++i) CHECK(back[i].as_number() == values[i]);
}

TEST_CASE("JSON strings, nesting and key order round trip", "[json]") {
  Json doc = Json::object();
  doc["zeta"] = "quote \" backslash \\ newline \n tab \t unicode \xC3\xA9";
  doc["alpha"] = Json::array();
  doc["alpha"].push_back(true);
  doc["alpha"].push_back(Json());
  doc["alpha"].push_back(Json::object());
  doc["n"] = 42;
  for (int indent : {-1, 1, 4}) {
    const Json back = parse_json(doc.dump(indent));
    CHECK(back.dump() == doc.dump());
    REQUIRE(back.as_object().size() == 3);
    CHECK(back.as_object()[0].first == "zeta");  // insertion order kept
    CHECK(back.at("zeta").as_string() == doc.at("zeta").as_string());
    CHECK(back.at("alpha")[1].is_null());
    CHECK(back.at("n").as_number() == 42);
  }
  CHECK(parse_json("\"\\u00e9\\ud83d\\ude00\"").as_string() == "\xC3\xA9\xF0\x9F\x98\x80");
}

TEST_CASE("malformed JSON names the file, line and column", "[json]") {
  CHECK_THAT(error_of(""), Catch::Contains("doc.json") && Catch::Contains("empty"));
  CHECK_THAT(error_of("{\n  \"a\": 1,\n  \"b\" 2\n}"),
             Catch::Contains("line 3") && Catch::Contains("expected ':'"));
  CHECK_THAT(error_of("[1, 2"), Catch::Contains("expected ',' or ']'"));
  CHECK_THAT(error_of("{\"a\": tru}"), Catch::Contains("unexpected character"));
  CHECK_THAT(error_of("\"abc"), Catch::Contains("unterminated string"));
  CHECK_THAT(error_of("1 2"), Catch::Contains("unexpected text"));
  CHECK_THAT(error_of("-"), Catch::Contains("malformed number"));
  CHECK_THAT(error_of("1e999"), Catch::Contains("out of range"));
  CHECK_THAT(error_of(std::string(100000, '[')), Catch::Contains("nesting"));
}

TEST_CASE("non-finite numbers are written as null", "[json]") {
  Json arr = Json::array();
  arr.push_back(std::numeric_limits<double>::quiet_NaN());
  arr.push_back(std::numeric_limits<double>::infinity());
  CHECK(arr.dump(-1) == "[null,null]");
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

  const Json doc = ulc::io::results_to_json({r});
  const Json& e = doc.at("results")[0];
  const double kDeg = 180.0 / 3.14159265358979323846;
  CHECK(e.at("rpy_deg")[0].as_number() == Approx(0.1 * kDeg));
  CHECK(e.at("rpy_deg")[1].as_number() == Approx(-0.2 * kDeg));
  CHECK(e.at("rpy_deg")[2].as_number() == Approx(1.3 * kDeg));
  const Eigen::Quaterniond q(
      e.at("rotation_quat_wxyz")[0].as_number(), e.at("rotation_quat_wxyz")[1].as_number(),
      e.at("rotation_quat_wxyz")[2].as_number(), e.at("rotation_quat_wxyz")[3].as_number());
  CHECK(q.toRotationMatrix().isApprox(r.T_base_target.linear(), 1e-12));
  CHECK(e.at("translation_m")[2].as_number() == 0.25);

  const auto back = ulc::io::results_from_json(parse_json(doc.dump()), "result.json");
  REQUIRE(back.size() == 1);
  CHECK(back[0].success);
  CHECK(back[0].T_base_target.isApprox(r.T_base_target, 1e-14));
  CHECK(*back[0].time_offset_s == 0.05);
  CHECK(back[0].covariance_6x6->isApprox(*r.covariance_6x6));
  CHECK(back[0].stages.at("terra").at("rotations_evaluated").as_number() == 1234);

  CHECK_THROWS_WITH(ulc::io::results_from_json(parse_json("{\"pairs\": []}"), "x.json"),
                    Catch::Contains("x.json") && Catch::Contains("results"));
}
