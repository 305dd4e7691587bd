#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "run_command.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/result_file.hpp"
#include "ulc_app_path.hpp"

namespace fs = std::filesystem;
using ulc_test::quote;
using ulc_test::run_command;

namespace {

using ulc_test::kUlc;

struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name) : path(fs::temp_directory_path() / name) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

Eigen::Isometry3d make_pose(double roll, double pitch, double yaw, Eigen::Vector3d t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ulc::rotation_from_rpy(roll, pitch, yaw);
  T.translation() = t;
  return T;
}

}  // namespace

TEST_CASE("ulc evaluate measures a result against the ground truth", "[app][evaluate]") {
  TempDir dir("ulc_test_evaluate");
  ulc::io::GroundTruth gt;
  const Eigen::Isometry3d truth = make_pose(0.1, 0.2, 1.5, {1.0, -0.5, 0.3});
  gt.pairs.push_back({"top", "left", truth, 0.05});
  ulc::io::write_ground_truth(dir.file("gt.json"), gt);

  // 0.5 degrees about z and 3 cm off: a success by the paper's criterion.
  ulc::io::PairResult r;
  r.base = "top";
  r.target = "left";
  r.success = true;
  r.status = "ok";
  r.T_base_target = make_pose(0, 0, 0.5 * M_PI / 180, {0.03, 0, 0}) * truth;
  r.T_base_target.translation() = truth.translation() + Eigen::Vector3d(0.03, 0, 0);
  r.time_offset_s = 0.047;
  ulc::io::write_result_file(dir.file("result.json"), {r});

  const auto run = run_command(kUlc + " evaluate --result " + quote(dir.file("result.json")) +
                               " --ground-truth " + quote(dir.file("gt.json")) + " --json");
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  const auto doc = ulc::io::parse_json(run.output);
  const auto& e = doc.at("pairs")[0];
  CHECK(e.at("e_rot_deg").get<double>() == Approx(0.5).epsilon(1e-6));
  CHECK(e.at("e_trans_m").get<double>() == Approx(0.03).epsilon(1e-9));
  CHECK(e.at("time_offset_error_s").get<double>() == Approx(-0.003).epsilon(1e-9));
  CHECK(e.at("success").get<bool>());

  // 2 degrees off fails the criterion: exit code 1, and the table says "no".
  r.T_base_target = make_pose(0, 0, 2.0 * M_PI / 180, {0, 0, 0}) * truth;
  ulc::io::write_result_file(dir.file("result.json"), {r});
  const auto failed = run_command(kUlc + " evaluate --result " + quote(dir.file("result.json")) +
                                  " --ground-truth " + quote(dir.file("gt.json")));
  INFO(failed.output);
  CHECK(failed.exit_code == 1);
  CHECK_THAT(failed.output, Catch::Contains("2.0000") && Catch::Contains(" no"));
}

TEST_CASE("ulc evaluate finds the reversed pair and inverts it", "[app][evaluate]") {
  TempDir dir("ulc_test_evaluate_reversed");
  ulc::io::GroundTruth gt;
  const Eigen::Isometry3d truth = make_pose(-0.3, 0.1, 2.0, {0.2, 1.5, -0.4});
  gt.pairs.push_back({"left", "top", truth.inverse(), -0.02});
  ulc::io::write_ground_truth(dir.file("gt.json"), gt);
  ulc::io::PairResult r;
  r.base = "top";
  r.target = "left";
  r.success = true;
  r.T_base_target = truth;
  r.time_offset_s = 0.02;
  ulc::io::write_result_file(dir.file("result.json"), {r});
  const auto run =
      run_command(kUlc + " evaluate --json --result " + quote(dir.file("result.json")) +
                  " --ground-truth " + quote(dir.file("gt.json")));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  const auto doc = ulc::io::parse_json(run.output);
  CHECK(doc.at("pairs")[0].at("e_rot_deg").get<double>() < 1e-6);
  CHECK(std::abs(doc.at("pairs")[0].at("time_offset_error_s").get<double>()) < 1e-12);
}

TEST_CASE("ulc reports bad usage and unreadable input with exit code 2", "[app][usage]") {
  TempDir dir("ulc_test_usage");
  auto expect_usage_error = [](const std::string& args, const std::string& message) {
    const auto run = run_command(kUlc + " " + args);
    INFO(args << "\n" << run.output);
    CHECK(run.exit_code == 2);
    CHECK_THAT(run.output, Catch::Contains(message));
  };
  expect_usage_error("", "usage");
  expect_usage_error("frobnicate", "unknown command 'frobnicate'");
  expect_usage_error("evaluate --result", "evaluate: --result: 1 required FILE missing");
  expect_usage_error("evaluate --result a.json --ground-truth b.json --bogus",
                     "evaluate: The following argument was not expected: --bogus");
  expect_usage_error("evaluate --result a.json", "evaluate: --ground-truth is required");
  expect_usage_error(
      "evaluate --result " + quote(dir.file("missing.json")) + " --ground-truth x.json",
      "missing.json: cannot open file");
  { std::ofstream(dir.file("broken.json")) << "{\"results\": ["; }
  expect_usage_error(
      "evaluate --result " + quote(dir.file("broken.json")) + " --ground-truth x.json",
      "broken.json: line 1, column 14: syntax error");
  const auto help = run_command(kUlc + " evaluate --help");
  CHECK(help.exit_code == 0);
  CHECK_THAT(help.output, Catch::Contains("--ground-truth"));
}

TEST_CASE("ulc --help and ulc <command> --help describe the commands", "[app][usage]") {
  const auto all = run_command(kUlc + " --help");
  CHECK(all.exit_code == 0);
  for (const char* command : {"calibrate", "simulate", "inspect", "export", "evaluate"}) {
    CHECK_THAT(all.output, Catch::Contains(std::string("  ") + command));
    for (const char* flag : {" --help", " -h"}) {
      const auto help = run_command(kUlc + " " + command + flag);
      INFO(command << flag << "\n" << help.output);
      CHECK(help.exit_code == 0);
      CHECK_THAT(help.output, Catch::Contains(std::string("Usage: ulc ") + command));
    }
  }
}
