// `ulc calibrate` end to end: on a tiny simulated 64-32 dataset (written by `ulc simulate`),
// --stages terra writes the result file of docs/design.md with a rotation near the ground truth;
// terra,jeep passes `ulc evaluate`; jeep alone takes --initial as numbers or as a result file;
// --stages hots is accepted and runs over every frame, and --synced-clocks skips the offset;
// a parked rig's recording is calibrated without a clock offset, HOTS skipped and the output
// saying so; a target that cannot be calibrated gives exit code 1 and still its entry; bad usage
// gives exit code 2 and one line naming the problem; and on the real croon_0003 sample TERRA finds
// both side LiDARs within 5 deg of the shipped calibration.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "run_command.hpp"
#include "test_paths.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/pcd.hpp"
#include "ulc/io/result_file.hpp"
#include "ulc_app_path.hpp"

namespace fs = std::filesystem;
using ulc_test::quote;
using ulc_test::run_command;

namespace {

using ulc_test::kUlc;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// A 0.6 s 64-32 drive (six frames per LiDAR; or `seconds`, and `ulc simulate`'s `more`
/// options) in its own temporary folder, removed afterwards.
struct Dataset {
  fs::path dir;
  explicit Dataset(const std::string& name, const std::string& seconds = "0.6",
                   const std::string& more = "")
      : dir(fs::temp_directory_path() / name) {
    fs::remove_all(dir);
    const auto run = run_command(kUlc + " simulate --quiet --scenario 64-32 --seconds " + seconds +
                                 " --seed 2" + more + " --out " + quote(dir.string()));
    INFO(run.output);
    REQUIRE(run.exit_code == 0);
  }
  ~Dataset() { fs::remove_all(dir); }
  std::string lidar(const std::string& name) const { return quote((dir / name).string()); }
  std::string file(const std::string& name) const { return (dir / name).string(); }
  std::string pair_args() const {
    return " --base " + lidar("lidar64") + " --target " + lidar("lidar32");
  }
  ulc::io::GroundTruth truth() const {
    return ulc::io::read_ground_truth((dir / "ground_truth.json").string());
  }
};

Eigen::Isometry3d true_extrinsic(const Dataset& d) {
  const auto gt = d.truth();
  const auto* p = gt.find_pair("lidar64", "lidar32");
  REQUIRE(p);
  return p->T_base_target;
}

/// "x y z roll pitch yaw" (metres, degrees) of T, as --initial takes it.
std::string xyz_rpy(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d t = T.translation();
  const Eigen::Vector3d rpy = ulc::rpy_from_rotation(T.linear()) / kDeg;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%.9f %.9f %.9f %.9f %.9f %.9f", t.x(), t.y(), t.z(), rpy.x(),
                rpy.y(), rpy.z());
  return buf;
}

/// `ulc evaluate --json` of a result file: the first pair's success.
bool evaluate_success(const Dataset& d, const std::string& result) {
  const auto run = run_command(kUlc + " evaluate --json --result " + quote(result) +
                               " --ground-truth " + quote(d.file("ground_truth.json")));
  INFO(run.output);
  const auto doc = ulc::io::parse_json(run.output);
  return run.exit_code == 0 && doc.at("pairs")[0].at("success").get<bool>();
}

}  // namespace

TEST_CASE("ulc calibrate --stages terra writes the result file of docs/design.md",
          "[app][calibrate]") {
  const Dataset d("ulc_test_calibrate_terra");
  const std::string out = d.file("result.json");
  const auto run = run_command(kUlc + " calibrate" + d.pair_args() +
                               " --stages terra --frame-index 1 --output " + quote(out));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  CHECK_THAT(run.output, Catch::Contains("lidar64 <- lidar32: ok"));
  CHECK_THAT(run.output, Catch::Contains("lidar32 terra: 100%"));  // plain progress when piped

  const auto results = ulc::io::read_result_file(out);
  REQUIRE(results.size() == 1);
  const auto& r = results[0];
  CHECK(r.base == "lidar64");
  CHECK(r.target == "lidar32");
  CHECK(r.success);
  CHECK(r.status == "ok");
  CHECK(r.T_base_target.translation() == Eigen::Vector3d::Zero());
  const auto e = ulc::pose_error(true_extrinsic(d), r.T_base_target);
  INFO("e_rot " << e.rotation_deg << " deg");
  CHECK(ulc::is_rotation_init_success(e));

  // Every field of docs/design.md, in its spelling.
  const auto doc = ulc::io::read_json_file(out);
  const auto& entry = doc.at("results")[0];
  for (const char* key :
       {"base", "target", "success", "status", "reason", "T_base_target", "translation_m",
        "rotation_quat_wxyz", "rpy_deg", "time_offset_s", "covariance_6x6", "stages", "timing_s"})
    CHECK(entry.contains(key));
  CHECK(entry.at("translation_m").size() == 3);
  CHECK(entry.at("rotation_quat_wxyz").size() == 4);
  CHECK(entry.at("rpy_deg").size() == 3);
  const auto& terra = entry.at("stages").at("terra");
  CHECK(terra.at("status").get<std::string>() == "ok");
  CHECK(terra.at("frame_index").get<double>() == 1);
  CHECK(terra.at("rotations_evaluated").get<double>() > 1000);
  CHECK(terra.at("d1_used_m").get<double>() > 0);
  CHECK_FALSE(entry.at("stages").contains("jeep"));
  for (const char* key : {"terra", "jeep", "odometry", "hots", "total"})
    CHECK(entry.at("timing_s").at(key).is_number());
}

TEST_CASE("ulc calibrate terra,jeep passes ulc evaluate", "[app][calibrate]") {
  const Dataset d("ulc_test_calibrate_full");
  const std::string out = d.file("result.json");
  const auto run =
      run_command(kUlc + " calibrate" + d.pair_args() +
                  " --synced-clocks --stages terra,jeep --threads 2 --output " + quote(out));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  const auto r = ulc::io::read_result_file(out);
  REQUIRE(r.size() == 1);
  CHECK(r[0].stages.at("jeep").at("status").get<std::string>() == "ok");
  CHECK(r[0].stages.at("jeep").at("frame_pairs").get<double>() == 5);
  // The start search ran (jeep/start_search.hpp): at least the guess's own basin, a start index.
  CHECK(r[0].stages.at("jeep").at("start_basins").get<double>() >= 1);
  CHECK(r[0].stages.at("jeep").at("start_chosen").get<double>() < 13);
  CHECK(evaluate_success(d, out));
}

TEST_CASE("ulc calibrate --stages jeep takes --initial as numbers or a result file",
          "[app][calibrate]") {
  const Dataset d("ulc_test_calibrate_initial");
  // 3 deg and 0.5 m off the truth, written in metres and degrees.
  Eigen::Isometry3d guess = true_extrinsic(d);
  guess.linear() = guess.linear() * ulc::rotation_from_rpy(2.0 * kDeg, -2.0 * kDeg, 1.0 * kDeg);
  guess.translation() += Eigen::Vector3d(0.3, -0.3, 0.25);
  const std::string numbers = d.file("from_numbers.json");
  const auto run = run_command(kUlc + " calibrate --quiet" + d.pair_args() +
                               " --synced-clocks --stages jeep --frames 4 --initial " +
                               quote(xyz_rpy(guess)) + " --output " + quote(numbers));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  const auto r = ulc::io::read_result_file(numbers);
  REQUIRE(r.size() == 1);
  CHECK_FALSE(r[0].stages.contains("terra"));
  CHECK(r[0].stages.at("jeep").at("frame_pairs").get<double>() == 4);
  // JEEP started from the guess as typed (to the 1e-9 printed digits).
  const auto start = ulc::io::json_to_isometry(r[0].stages.at("jeep").at("initial_T_base_target"),
                                               numbers, "initial");
  CHECK(ulc::pose_error(guess, start).rotation_deg < 1e-6);
  CHECK(ulc::pose_error(guess, start).translation_m < 1e-6);
  CHECK(evaluate_success(d, numbers));

  // A result file as the guess: a terra-only result (rotation, zero translation) for the pair.
  ulc::io::PairResult seed;
  seed.base = "lidar64";
  seed.target = "lidar32";
  seed.T_base_target = guess;
  ulc::io::write_result_file(d.file("seed.json"), {seed});
  const std::string from_file = d.file("from_file.json");
  const auto again = run_command(kUlc + " calibrate --quiet" + d.pair_args() +
                                 " --synced-clocks --stages jeep --frames 4 --initial " +
                                 quote(d.file("seed.json")) + " --output " + quote(from_file));
  INFO(again.output);
  REQUIRE(again.exit_code == 0);
  const auto r2 = ulc::io::read_result_file(from_file);
  REQUIRE(r2.size() == 1);
  // The same guess gives the same run, to the digits the first guess was printed with.
  CHECK(ulc::pose_error(r[0].T_base_target, r2[0].T_base_target).rotation_deg < 1e-3);
  CHECK(evaluate_success(d, from_file));
}

TEST_CASE("ulc calibrate --format yaml, --merged-cloud and --report write what they promise",
          "[app][calibrate]") {
  const Dataset d("ulc_test_calibrate_outputs");
  Eigen::Isometry3d guess = true_extrinsic(d);
  guess.translation() += Eigen::Vector3d(0.2, 0.1, -0.1);
  const std::string yaml = d.file("result.yaml"), fused = d.file("fused.pcd"),
                    report = d.file("report.png");
  const auto run = run_command(kUlc + " calibrate --quiet" + d.pair_args() +
                               " --synced-clocks --stages jeep --frames 4 --initial " +
                               quote(xyz_rpy(guess)) + " --format yaml --output " + quote(yaml) +
                               " --merged-cloud " + quote(fused) + " --report " + quote(report));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);

  // YAML: the matrix rows follow T_base_target and give the calibrated transform.
  std::FILE* f = std::fopen(yaml.c_str(), "rb");
  REQUIRE(f);
  std::string text(1 << 16, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), f));
  std::fclose(f);
  CHECK(text.find("static_transform_publisher: ") != std::string::npos);
  CHECK(text.find("<parent link=\"lidar64\"/>") != std::string::npos);
  const auto at = text.find("translation_m: [");
  REQUIRE(at != std::string::npos);
  Eigen::Vector3d t;
  REQUIRE(std::sscanf(text.c_str() + at, "translation_m: [%lf, %lf, %lf]", &t.x(), &t.y(),
                      &t.z()) == 3);
  CHECK((t - true_extrinsic(d).translation()).norm() < 0.1);

  // Fused cloud: both LiDARs' first frames, the target's moved onto the base's surfaces.
  const auto base =
      ulc::io::read_pcd<std::vector<Eigen::Vector3f>>((d.dir / "lidar64" / "000000.pcd").string());
  const auto target =
      ulc::io::read_pcd<std::vector<Eigen::Vector3f>>((d.dir / "lidar32" / "000000.pcd").string());
  const auto merged = ulc::io::read_pcd<std::vector<Eigen::Vector3f>>(fused);
  REQUIRE(merged.size() == base.size() + target.size());
  CHECK(merged.front().isApprox(base.front()));
  const Eigen::Isometry3f T = true_extrinsic(d).cast<float>();
  CHECK((merged[base.size()] - T * target.front()).norm() < 0.1f);

  // Report: a PNG file (signature) of non-trivial size.
  std::FILE* png = std::fopen(report.c_str(), "rb");
  REQUIRE(png);
  unsigned char signature[8] = {};
  CHECK(std::fread(signature, 1, 8, png) == 8);
  std::fseek(png, 0, SEEK_END);
  CHECK(std::ftell(png) > 10000);
  std::fclose(png);
  CHECK(signature[1] == 'P');
  CHECK(signature[2] == 'N');
  CHECK(signature[3] == 'G');

  // A format that does not exist is bad usage.
  const auto bad = run_command(kUlc + " calibrate --quiet" + d.pair_args() +
                               " --stages terra --format xml --output " + quote(yaml));
  CHECK(bad.exit_code == 2);
  CHECK(bad.output.find("--format") != std::string::npos);
}

TEST_CASE("ulc calibrate --stages hots is accepted and runs odometry and HOTS over every frame",
          "[app][calibrate][hots]") {
  const Dataset d("ulc_test_calibrate_hots");
  // 0.3 deg and 3 cm off the truth: what JEEP leaves for HOTS.
  Eigen::Isometry3d guess = true_extrinsic(d);
  guess.linear() = guess.linear() * ulc::rotation_from_rpy(0.2 * kDeg, -0.2 * kDeg, 0.1 * kDeg);
  guess.translation() += Eigen::Vector3d(0.02, -0.02, 0.01);
  const std::string out = d.file("result.json");
  const auto run =
      run_command(kUlc + " calibrate --quiet" + d.pair_args() + " --stages hots --initial " +
                  quote(xyz_rpy(guess)) + " --output " + quote(out));
  INFO(run.output);
  // Six frames are enough for the odometry and the hierarchy but too few for the time
  // synchronisation: the stage runs and fails, and the entry says so (the full pipeline's
  // success on a longer drive is tests/calibrate/test_hots_stage.cpp).
  CHECK(run.exit_code == 1);
  CHECK_THAT(run.output, Catch::Contains("odometry"));
  const auto r = ulc::io::read_result_file(out);
  REQUIRE(r.size() == 1);
  CHECK_FALSE(r[0].success);
  CHECK(r[0].status == "hots_failed");
  CHECK_THAT(r[0].reason, Catch::Contains("HOTS: time_sync_failed"));
  CHECK_FALSE(r[0].stages.contains("terra"));
  CHECK_FALSE(r[0].stages.contains("jeep"));
  const auto& hots = r[0].stages.at("hots");
  CHECK(hots.at("frames_base").get<double>() == 6);  // every frame of the 0.6 s drive
  CHECK(hots.at("frames_target").get<double>() == 6);
  CHECK(hots.at("odometry_status").get<std::string>() == "ok");
  CHECK(hots.at("windows").get<double>() > 0);
  CHECK(r[0].timing_s.at("odometry").get<double>() > 0.0);
  CHECK(r[0].timing_s.at("hots").get<double>() > 0.0);
  // A failed HOTS keeps the extrinsic it started from (the guess, to its printed digits).
  CHECK(ulc::pose_error(guess, r[0].T_base_target).rotation_deg < 1e-6);
  CHECK(ulc::pose_error(guess, r[0].T_base_target).translation_m < 1e-6);
  CHECK(!r[0].covariance_6x6);

  // --synced-clocks: no offset to estimate, so no synchronisation to fail, and none checked.
  const auto synced =
      run_command(kUlc + " calibrate --quiet --synced-clocks" + d.pair_args() +
                  " --stages hots --initial " + quote(xyz_rpy(guess)) + " --output " + quote(out));
  INFO(synced.output);
  const auto rs = ulc::io::read_result_file(out);
  REQUIRE(rs.size() == 1);
  CHECK_THAT(rs[0].reason, !Catch::Contains("time_sync"));
  REQUIRE(rs[0].time_offset_s);
  CHECK(*rs[0].time_offset_s == 0.0);
  const auto& synced_hots = rs[0].stages.at("hots");
  CHECK(synced_hots.at("time_offset_checked").get<bool>() == false);
  CHECK(synced_hots.at("time_sync_pairs").get<double>() == 0);  // the synchronisation never ran
  // Every cross-link registration is in the file, one row each; the counts agree with it.
  const auto& registrations = synced_hots.at("cross_link_registrations");
  CHECK(registrations.at("columns").size() == 6);
  const auto& rows = registrations.at("rows");
  CHECK(rows.size() == synced_hots.at("cross_links_attempted").get<std::size_t>());
  std::size_t converged = 0;
  for (const auto& row : rows) converged += row.at(1).get<int>();
  CHECK(converged == synced_hots.at("cross_links_converged").get<std::size_t>());

  // --base-odometry: the base's own odometry and HOTS's preparation of its frames, done for the
  // first target and reused by the second (the same LiDAR under another name), whose answer is
  // then the first's.
  const auto shared = run_command(
      kUlc + " calibrate --quiet --synced-clocks --base-odometry" + d.pair_args() + " --target " +
      quote((d.dir / "lidar32").string() + "=again") + " --no-cycles --stages hots --initial " +
      quote(xyz_rpy(guess)) + " --output " + quote(out));
  INFO(shared.output);
  const auto rb = ulc::io::read_result_file(out);
  REQUIRE(rb.size() == 2);
  CHECK(rb[1].target == "again");
  CHECK(rb[0].stages.at("hots").at("odometry_reused").get<bool>() == false);
  CHECK(rb[1].stages.at("hots").at("odometry_reused").get<bool>() == true);
  CHECK(rb[1].stages.at("hots").at("base_prepared_reused").get<bool>() == true);
  CHECK(rb[0].T_base_target.isApprox(rb[1].T_base_target, 1e-12));
  CHECK(rb[0].status == rb[1].status);
  CHECK(rb[0].stages.at("hots").at("odometry").get<std::string>() == "base");
  CHECK(rs[0].stages.at("hots").at("odometry_reused").get<bool>() == false);    // the default:
  CHECK(rs[0].stages.at("hots").at("odometry").get<std::string>() == "joint");  // a short drive
  CHECK_THAT(rs[0].stages.at("hots").at("odometry_choice").get<std::string>(),
             Catch::Contains("lasts"));

  // One odometry or the other, not both.
  const auto both = run_command(kUlc + " calibrate --quiet --base-odometry --joint-odometry" +
                                d.pair_args() + " --output " + quote(out));
  CHECK(both.exit_code == 2);
  CHECK_THAT(both.output, Catch::Contains("excludes"));
}

TEST_CASE("a target that cannot be calibrated: exit code 1, and its entry says why",
          "[app][calibrate]") {
  const Dataset d("ulc_test_calibrate_fail");
  // A target that sees only a wall 1.5 m away: TERRA has nothing beyond d1 to compare.
  std::vector<Eigen::Vector3f> wall;
  for (int i = -30; i <= 30; ++i)
    for (int j = -30; j <= 30; ++j) wall.emplace_back(1.5f, 0.05f * i, 0.05f * j);
  ulc::io::write_pcd(d.file("wall.pcd"), wall);
  const std::string out = d.file("result.json");
  const auto run = run_command(kUlc + " calibrate --stages terra --base " + d.lidar("lidar64") +
                               " --target " + d.lidar("lidar32") + " --target " +
                               quote(d.file("wall.pcd")) + " --output " + quote(out));
  INFO(run.output);
  CHECK(run.exit_code == 1);
  CHECK_THAT(run.output, Catch::Contains("lidar64 <- wall: terra_failed"));
  const auto r = ulc::io::read_result_file(out);
  REQUIRE(r.size() == 2);
  CHECK(r[0].success);
  CHECK(r[1].target == "wall");  // a single frame file is named by its stem
  CHECK_FALSE(r[1].success);
  CHECK(r[1].status == "terra_failed");
  CHECK_THAT(r[1].reason, Catch::Contains("no_overlap"));
}

TEST_CASE("ulc calibrate reports bad usage and unreadable input with exit code 2",
          "[app][calibrate][usage]") {
  const Dataset d("ulc_test_calibrate_usage");
  auto usage = [&](const std::string& args, const std::string& message) {
    const auto run = run_command(kUlc + " calibrate " + args);
    INFO(args << "\n" << run.output);
    CHECK(run.exit_code == 2);
    CHECK_THAT(run.output, Catch::Contains(message));
    // One line: the problem, nothing else.
    CHECK(std::count(run.output.begin(), run.output.end(), '\n') == 1);
  };
  const std::string missing = d.file("no_such_lidar");
  usage("--base " + quote(missing) + " --target " + d.lidar("lidar32"),
        missing + ": no such folder or file");
  usage(d.pair_args() + " --stages jeep --initial '1 2 3'",
        "'--initial' expects \"x y z roll pitch yaw\"");
  usage(d.pair_args() + " --stages jeep --initial '1 2 3 4 5 six'", "got '1 2 3 4 5 six'");
  usage(d.pair_args() + " --stages jeep --initial " + quote(d.file("missing.json")),
        "missing.json: cannot open file");
  usage(d.pair_args() + " --stages terra,icp", "unknown stage 'icp'");
  usage(d.pair_args() + " --stages jeep,terra", "cannot follow");
  usage(d.pair_args() + " --stages jeep", "needs an initial extrinsic");
  usage(d.pair_args() + " --stages terra --initial '0 0 0 0 0 0'", "'--initial' is only used");
  usage(d.pair_args() + " --frame-index 6", "--frame-index 6 is past the last frame of");
  usage(d.pair_args() + " --frame-index -1", "--frame-index: Value -1 not in range");
  usage(d.pair_args() + " --frames 0", "--frames: Value 0 not in range");
  usage(d.pair_args() + " --threads 0", "--threads: Value 0 not in range");
  usage(d.pair_args() + " --format xml", "--format: xml not in {json,yaml}");
  usage(d.pair_args() + " --frame-time now", "--frame-time: now not in {header,receive}");
  usage(d.pair_args() + " --output " + quote(d.file("nowhere/result.json")),
        "nowhere/result.json: no such folder");
  usage("--target " + d.lidar("lidar32"), "calibrate: --base is required");
  usage("--base " + d.lidar("lidar64"), "calibrate: --target is required");
  usage(d.pair_args() + " --second-look", "not expected: --second-look");  // removed
  const auto help = run_command(kUlc + " calibrate --help");
  CHECK(help.exit_code == 0);
  CHECK_THAT(help.output, Catch::Contains("--initial") && Catch::Contains("--frame-index"));
}

/// `ulc calibrate <extra> --base top --target left --target right` on croon_0003: each result
/// with its error against the shipped calibration.
std::vector<std::pair<ulc::io::PairResult, ulc::PoseError>> calibrate_croon(
    const fs::path& dir, const std::string& extra) {
  const fs::path out = fs::temp_directory_path() / "ulc_test_calibrate_croon.json";
  const auto run = run_command(
      kUlc + " calibrate --quiet" + extra + " --base " + quote((dir / "top.pcd").string()) +
      " --target " + quote((dir / "left.pcd").string()) + " --target " +
      quote((dir / "right.pcd").string()) + " --output " + quote(out.string()));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  const auto results = ulc::io::read_result_file(out.string());
  fs::remove(out);
  const auto gt = ulc::io::read_ground_truth((dir / "ground_truth.json").string());
  REQUIRE(results.size() == 2);
  std::vector<std::pair<ulc::io::PairResult, ulc::PoseError>> out_pairs;
  for (const auto& r : results) {
    const auto* truth = gt.find_pair(r.base, r.target);
    REQUIRE(truth);
    out_pairs.emplace_back(r, ulc::pose_error(truth->T_base_target, r.T_base_target));
  }
  return out_pairs;
}

TEST_CASE("real sample: TERRA finds both side LiDARs of croon_0003 with no guess",
          "[app][calibrate][real]") {
  const auto dir = ulc_test::croon_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "croon_0003 sample not found next to the checkout");
  for (const auto& [r, e] : calibrate_croon(dir, " --stages terra")) {
    INFO(r.base << " <- " << r.target << ": e_rot " << e.rotation_deg << " deg");
    CHECK(e.rotation_deg < 5.0);
  }
}

TEST_CASE(
    "real sample: the default stages calibrate croon_0003's single frames within 1 deg and "
    "10 cm, HOTS skipped",
    "[app][calibrate][real]") {
  const auto dir = ulc_test::croon_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "croon_0003 sample not found next to the checkout");
  for (const auto& [r, e] : calibrate_croon(dir, "")) {
    INFO(r.base << " <- " << r.target << ": e_rot " << e.rotation_deg << " deg, e_trans "
                << e.translation_m << " m");
    CHECK(r.success);
    CHECK(r.stages.at("hots").at("status").get<std::string>() == "skipped");
    CHECK(e.rotation_deg < 1.0);
    CHECK(e.translation_m < 0.10);
  }
}

TEST_CASE("ulc calibrate names a LiDAR without point times and says the offset was not estimated",
          "[app][calibrate][vouch]") {
  const Dataset d("ulc_test_calibrate_untimed");
  // The VLP-32C's frames written again without their per-point times.
  const auto strip = run_command(kUlc + " simulate --quiet --scenario 64-32 --seconds 0.6 " +
                                 "--seed 2 --no-point-times lidar32 --out " + quote(d.file("")));
  INFO(strip.output);
  REQUIRE(strip.exit_code == 0);
  const std::string out = d.file("result.json");
  const auto run = run_command(kUlc + " calibrate --quiet" + d.pair_args() +
                               " --synced-clocks --stages terra,jeep --output " + quote(out));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  CHECK_THAT(run.output, Catch::Contains("times   lidar32 (synthesised_from_azimuth)"));
  const auto r = ulc::io::read_result_file(out);
  REQUIRE(r.size() == 1);
  CHECK(r[0].point_times.at("base").at("source").get<std::string>() == "per_point");
  CHECK(r[0].point_times.at("target").at("source").get<std::string>() ==
        "synthesised_from_azimuth");
  // Frames are read on demand and counted as the stages read them: TERRA's local maps (built
  // for the motion frame) read all 6, JEEP 5 of them.
  CHECK(r[0].point_times.at("target").at("frames_without").get<double>() == 6);
  CHECK(r[0].clock.at("source").get<std::string>() == "given");
  CHECK(evaluate_success(d, out));

  // No offset given: moving, six frames cannot bound a lag, and the result says so.
  const auto unsynced = run_command(kUlc + " calibrate --quiet" + d.pair_args() +
                                    " --stages terra,jeep --output " + quote(out));
  INFO(unsynced.output);
  CHECK(unsynced.exit_code == 1);
  CHECK_THAT(unsynced.output, Catch::Contains("time_offset_unestimated"));
  const auto refused = ulc::io::read_result_file(out);
  REQUIRE(refused.size() == 1);
  CHECK_FALSE(refused[0].success);
  CHECK(refused[0].clock.at("source").get<std::string>() == "not_estimated");
  CHECK_THAT(refused[0].reason, Catch::Contains("the clock offset was not estimated"));

  const auto unknown = run_command(kUlc + " simulate --quiet --scenario 64-32 --seconds 0.3 " +
                                   "--no-point-times lidar99 --out " + quote(d.file("x")));
  CHECK(unknown.exit_code == 2);
  CHECK_THAT(unknown.output, Catch::Contains("no LiDAR named 'lidar99'"));
}

TEST_CASE("ulc calibrate --budget calibrates the best stretch of a longer drive and says which",
          "[app][calibrate][selection]") {
  const Dataset d("ulc_test_calibrate_budget", "10");
  const std::string out = d.file("result.json");
  const auto run = run_command(kUlc + " calibrate" + d.pair_args() +
                               " --synced-clocks --budget 5 --output " + quote(out));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  CHECK_THAT(run.output, Catch::Contains("survey: 100% (100/100)"));  // frames surveyed
  CHECK_THAT(run.output, Catch::Contains("s left"));                  // the time still to go
  CHECK_THAT(run.output, Catch::Contains("stretch "));
  const auto results = ulc::io::read_result_file(out);
  REQUIRE(results.size() == 1);
  const auto& sel = results[0].stages.at("selection");
  CHECK(sel.at("applied").get<bool>());
  CHECK(sel.at("budget_s").get<double>() == 5.0);
  CHECK(sel.at("drive_s").get<double>() == Approx(9.9).margin(0.05));
  const double start = sel.at("start_s").get<double>(), end = sel.at("end_s").get<double>();
  CHECK(end - start == Approx(5.0));
  const auto& windows = sel.at("windows");
  REQUIRE(windows.size() == 2);  // from 0 s, and the last 5 s
  const auto chosen = sel.at("chosen").get<std::size_t>();
  REQUIRE(chosen < windows.size());
  CHECK(windows[chosen].at("start_s").get<double>() == start);
  for (const auto& w : windows)
    CHECK(w.at("score").get<double>() <= windows[chosen].at("score").get<double>());
  // HOTS ran on the stretch alone, and the answer is right.
  CHECK(results[0].stages.at("hots").at("frames_base").get<double>() <= 51);
  CHECK(evaluate_success(d, out));
}

TEST_CASE("ulc calibrate on a parked rig's recording: HOTS skipped, no clock offset needed",
          "[app][calibrate][stillness]") {
  const Dataset d("ulc_test_calibrate_parked", "1.5", " --parked-at 3");
  const std::string out = d.file("result.json");
  const auto run =
      run_command(kUlc + " calibrate --quiet" + d.pair_args() + " --output " + quote(out));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  CHECK_THAT(run.output, Catch::Contains("parked  the rig stood still"));
  const auto results = ulc::io::read_result_file(out);
  REQUIRE(results.size() == 1);
  const auto& hots = results[0].stages.at("hots");
  CHECK(hots.at("status").get<std::string>() == "skipped");
  CHECK(hots.at("stillness").at("still").get<bool>());
  CHECK(evaluate_success(d, out));

  const auto bad = run_command(kUlc + " simulate --quiet --scenario 64-32 --seconds 0.3 " +
                               "--parked-at -1 --out " + quote(d.file("x")));
  CHECK(bad.exit_code == 2);
  CHECK_THAT(bad.output, Catch::Contains("'--parked-at' must be in [0, 3600] s"));
}
