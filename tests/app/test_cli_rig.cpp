// `ulc calibrate` on a rig end to end: the blind-spot rig (campus-bs, 0.6 s, decimated 4x,
// written as a dataset folder) with the left Bpearl as base. The right Bpearl looks into the
// opposite half-space: it fails against the base and is calibrated through the Helios whose own
// calibration agreed best ("via" in the result file); the other pairs of targets close their
// cycles with the base ("cycles"). Every target passes `ulc evaluate`, which shows the route
// and the closures. With --no-route the
// right Bpearl fails (exit code 1, its entry says why); --no-cycles writes no cycles; two
// LiDARs with one name are bad usage (exit code 2).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "run_command.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/result_file.hpp"
#include "ulc/sim/dataset_writer.hpp"
#include "ulc/sim/simulate.hpp"
#include "ulc_app_path.hpp"

namespace fs = std::filesystem;
using ulc_test::quote;
using ulc_test::run_command;

namespace {

using ulc_test::kUlc;

/// campus-bs with the left Bpearl first (the base), 0.6 s, every 4th sample, in a temporary
/// folder removed afterwards.
struct RigDataset {
  fs::path dir;
  explicit RigDataset(const std::string& name) : dir(fs::temp_directory_path() / name) {
    fs::remove_all(dir);
    ulc::sim::ScenarioSpec spec = *ulc::sim::scenario("campus-bs");
    std::vector<ulc::sim::LidarMount> lidars;
    for (const char* n : {"bpearl_left", "helios_front", "helios_rear", "bpearl_right"})
      for (const auto& l : spec.lidars)
        if (l.name == n) lidars.push_back(l);
    REQUIRE(lidars.size() == 4);
    spec.lidars = lidars;
    spec.pairs.clear();  // the truth of any pair comes from the mounts
    ulc::sim::SimulationOptions o;
    o.seconds = 0.6;
    o.seed = 1;
    o.decimation = 4;
    const auto sim = ulc::sim::simulate(spec, o);
    REQUIRE(sim.ok());
    ulc::sim::write_dataset(dir, sim.dataset);
  }
  ~RigDataset() { fs::remove_all(dir); }
  std::string lidar(const std::string& name) const { return quote((dir / name).string()); }
  std::string file(const std::string& name) const { return (dir / name).string(); }
  Eigen::Isometry3d truth(const std::string& base, const std::string& target) const {
    const auto gt = ulc::io::read_ground_truth(file("ground_truth.json"));
    const auto* a = gt.find_lidar(base);
    const auto* b = gt.find_lidar(target);
    REQUIRE(a);
    REQUIRE(b);
    return a->T_vehicle_lidar.inverse() * b->T_vehicle_lidar;
  }
};

}  // namespace

TEST_CASE("ulc calibrate on a rig: a route through another LiDAR, cycle closures, evaluate",
          "[app][calibrate][rig]") {
  const RigDataset d("ulc_test_cli_rig");
  const std::string out = d.file("result.json");
  const auto run = run_command(kUlc + " calibrate --synced-clocks --stages terra,jeep --base " +
                               d.lidar("bpearl_left") + " --target " + d.lidar("helios_front") +
                               " --target " + d.lidar("helios_rear") + " --target " +
                               d.lidar("bpearl_right") + " --output " + quote(out));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);  // every target calibrated, one of them routed

  const ulc::io::ResultDocument doc = ulc::io::read_result_document(out);
  REQUIRE(doc.results.size() == 3);
  for (const auto& r : doc.results) {
    const auto e = ulc::pose_error(d.truth(r.base, r.target), r.T_base_target);
    INFO(r.target << ": " << r.reason << "; e_rot " << e.rotation_deg << " deg, e_trans "
                  << e.translation_m << " m");
    CHECK(r.success);
    CHECK(r.base == "bpearl_left");
    CHECK(e.rotation_deg < 0.5);
    CHECK(e.translation_m < 0.05);
  }
  const auto& front = doc.results[0];
  const auto& rear = doc.results[1];
  const auto& right = doc.results[2];
  CHECK(right.target == "bpearl_right");
  CHECK(front.via.empty());
  CHECK(rear.via.empty());
  // Routed through the Helios whose own calibration agreed best with the base (JEEP's
  // acceptance overlap, then the name).
  const double front_overlap = front.stages.at("jeep").at("overlap").get<double>();
  const double rear_overlap = rear.stages.at("jeep").at("overlap").get<double>();
  const std::string via = rear_overlap > front_overlap ? "helios_rear" : "helios_front";
  const std::string other = via == "helios_rear" ? "helios_front" : "helios_rear";
  CHECK(right.via == via);
  CHECK(right.direct_status == "jeep_failed");
  CHECK_FALSE(right.direct_reason.empty());
  CHECK_THAT(right.reason, Catch::StartsWith("calibrated through " + via));
  CHECK_THAT(run.output, Catch::Contains("bpearl_right via " + via + " terra: "));
  CHECK_THAT(run.output, Catch::Contains("route   bpearl_left <- " + via +
                                         " <- bpearl_right (direct: jeep_failed)"));
  // In the file: "via" and "direct" on the routed entry only.
  const auto json = ulc::io::read_json_file(out);
  CHECK(json.at("results")[2].at("via").get<std::string>() == via);
  CHECK(json.at("results")[2].at("direct").at("status").get<std::string>() == "jeep_failed");
  CHECK_FALSE(json.at("results")[0].contains("via"));
  CHECK_FALSE(json.at("results")[0].contains("direct"));

  // Cycles in target order; the route's own pair is no check and is left out.
  REQUIRE(doc.cycles.size() == 2);
  CHECK(doc.cycles[0].lidars ==
        std::vector<std::string>{"bpearl_left", "helios_front", "helios_rear"});
  CHECK(doc.cycles[1].lidars == std::vector<std::string>{"bpearl_left", other, "bpearl_right"});
  for (const auto& c : doc.cycles) {
    INFO(c.lidars[1] << " -> " << c.lidars[2] << ": " << c.status << " " << c.reason);
    CHECK(c.status == "ok");
    REQUIRE(c.rotation_deg);
    REQUIRE(c.translation_m);
    CHECK(*c.rotation_deg < 0.5);
    CHECK(*c.translation_m < 0.05);
  }
  CHECK_THAT(run.output,
             Catch::Contains("cycle bpearl_left -> helios_front -> helios_rear -> bpearl_left: "
                             "closure "));

  const auto ev = run_command(kUlc + " evaluate --result " + quote(out) + " --ground-truth " +
                              quote(d.file("ground_truth.json")));
  INFO(ev.output);
  CHECK(ev.exit_code == 0);
  CHECK_THAT(ev.output, Catch::Contains("yes (via " + via + ")"));
  CHECK_THAT(ev.output, Catch::Contains("cycle bpearl_left -> helios_front -> helios_rear -> "
                                        "bpearl_left: closure "));
}

TEST_CASE("ulc calibrate --no-route leaves the unseen target failed; --no-cycles writes none",
          "[app][calibrate][rig]") {
  const RigDataset d("ulc_test_cli_rig_flags");
  const std::string out = d.file("result.yaml");
  const auto run = run_command(
      kUlc + " calibrate --quiet --synced-clocks --no-route --no-cycles --stages " +
      "terra,jeep --base " + d.lidar("bpearl_left") + " --target " + d.lidar("helios_front") +
      " --target " + d.lidar("bpearl_right") + " --format yaml --output " + quote(out));
  INFO(run.output);
  CHECK(run.exit_code == 1);  // ran, but one target did not calibrate
  CHECK_THAT(run.output, Catch::Contains("bpearl_left <- bpearl_right: jeep_failed"));
  CHECK_THAT(run.output, !Catch::Contains("cycle "));
  CHECK_THAT(run.output, !Catch::Contains("route "));
  std::FILE* f = std::fopen(out.c_str(), "rb");
  REQUIRE(f);
  std::string text(1 << 16, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), f));
  std::fclose(f);
  CHECK(text.find("target: \"bpearl_right\"") != std::string::npos);
  CHECK(text.find("success: false") != std::string::npos);
  CHECK(text.find("via:") == std::string::npos);
  CHECK(text.find("cycles:") == std::string::npos);
}

TEST_CASE("ulc calibrate: two LiDARs with one name are bad usage", "[app][calibrate][rig][usage]") {
  const RigDataset d("ulc_test_cli_rig_usage");
  const auto run = run_command(kUlc + " calibrate --stages terra --base " + d.lidar("bpearl_left") +
                               " --target " + d.lidar("bpearl_left"));
  INFO(run.output);
  CHECK(run.exit_code == 2);
  CHECK_THAT(run.output,
             Catch::Contains("two LiDARs are named '") && Catch::Contains("bpearl_left'"));
  CHECK(std::count(run.output.begin(), run.output.end(), '\n') == 1);
}
