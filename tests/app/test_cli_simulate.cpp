#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "run_command.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/pcd.hpp"
#include "ulc/io/sequence.hpp"
#include "ulc_app_path.hpp"

namespace fs = std::filesystem;
using ulc_test::quote;
using ulc_test::run_command;

namespace {

using ulc_test::kUlc;

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST_CASE("ulc simulate writes the dataset folder of docs/design.md", "[app][simulate]") {
  const fs::path dir = fs::temp_directory_path() / "ulc_test_simulate";
  fs::remove_all(dir);
  const auto run = run_command(kUlc + " simulate --scenario 64-32 --seconds 0.25 --seed 3 --out " +
                               quote(dir.string()) + " --time-offset 0.02 --preview " +
                               quote((dir / "preview.png").string()));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  CHECK_THAT(run.output, Catch::Contains("simulate: 100%"));  // plain progress when piped

  const auto gt = ulc::io::read_ground_truth((dir / "ground_truth.json").string());
  REQUIRE(gt.lidars.size() == 2);
  REQUIRE(gt.pairs.size() == 1);
  const auto& pair = gt.pairs[0];
  CHECK(*pair.time_offset_s == Approx(0.02));
  const auto* base = gt.find_lidar(pair.base);
  const auto* target = gt.find_lidar(pair.target);
  REQUIRE(base);
  REQUIRE(target);
  // The pair's transform is the one implied by the two mounts.
  CHECK(pair.T_base_target.isApprox(base->T_vehicle_lidar.inverse() * target->T_vehicle_lidar,
                                    1e-12));
  // Mounts 0.5..3 m apart, as on a real vehicle.
  const double lever = pair.T_base_target.translation().norm();
  CHECK(lever >= 0.5);
  CHECK(lever <= 3.0);

  for (const auto& lidar : gt.lidars) {
    const ulc::io::Sequence seq(dir / lidar.name);
    CHECK(seq.time_source() == ulc::io::FrameTimeSource::timestamps_file);
    REQUIRE(seq.size() >= 2);
    ulc::io::ReadStats stats;
    const auto cloud = ulc::io::read_pcd<ulc::PointCloud<float>>(seq.frame(0).path, &stats);
    CHECK(stats.encoding == "binary");
    CHECK(stats.fields == std::vector<std::string>{"x", "y", "z", "intensity", "t"});
    CHECK(cloud.size() > 1000);
    CHECK(cloud.has_times());
  }
  CHECK(fs::file_size(dir / "trajectory.txt") > 0);
  CHECK(fs::file_size(dir / "preview.png") > 1000);

  // The same seed writes byte-identical frames.
  const fs::path again = dir / "again";
  REQUIRE(run_command(kUlc + " simulate --quiet --scenario 64-32 --seconds 0.25 --seed 3 --out " +
                      quote(again.string()) + " --time-offset 0.02")
              .exit_code == 0);
  for (const auto& lidar : gt.lidars)
    CHECK(read_all(dir / lidar.name / "000001.pcd") == read_all(again / lidar.name / "000001.pcd"));
  CHECK(read_all(dir / "ground_truth.json") == read_all(again / "ground_truth.json"));
  fs::remove_all(dir);
}

TEST_CASE("ulc simulate lists scenarios and rejects bad values with exit code 2",
          "[app][simulate][usage]") {
  const auto list = run_command(kUlc + " simulate --list");
  CHECK(list.exit_code == 0);
  for (const char* name : {"64-32", "32-16", "horizon-tele", "64-horizon", "32-avia", "64-tele",
                           "16-tele", "32-mid40", "colorful", "ring-5x16", "pitched-90",
                           "side-bpearl", "upside-down", "offset-50ms", "highway", "tunnel"})
    CHECK_THAT(list.output, Catch::Contains(name));

  auto usage = [](const std::string& args, const std::string& message) {
    const auto run = run_command(kUlc + " simulate " + args);
    INFO(args << "\n" << run.output);
    CHECK(run.exit_code == 2);
    CHECK_THAT(run.output, Catch::Contains(message));
  };
  usage("--scenario nope --out /tmp/x", "unknown scenario 'nope'");
  usage("--scenario 64-32", "simulate: --out is required");
  usage("--out /tmp/x", "simulate: --scenario is required");
  usage("--scenario 64-32 --out /tmp/x --seconds -1", "--seconds");
  usage("--scenario 64-32 --out /tmp/x --seconds abc", "Could not convert: --seconds = abc");
  usage("--scenario 64-32 --out /tmp/x --seed -4", "--seed");
  usage("--scenario 64-32 --out /tmp/x --rate 0", "--rate");
  usage("--scenario 64-32 --out /tmp/x --steering-ramp -2", "--steering-ramp");

  const fs::path ramped = fs::temp_directory_path() / "ulc_test_simulate_ramp";
  fs::remove_all(ramped);
  const auto run = run_command(kUlc + " simulate --scenario 32-16 --seconds 0.1 --quiet " +
                               "--steering-ramp 6 --out " + quote(ramped.string()));
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(fs::exists(ramped / "ground_truth.json"));
  fs::remove_all(ramped);
}
