// `ulc` on recordings: a simulated rig written as a ROS 1 bag, an MCAP file and a rosbag2 folder
// calibrates to the same extrinsic as from its frame folders; `ulc inspect` lists the topics of
// bags other tools wrote exactly as their README says; `ulc export` writes the frames back;
// topics that are missing or not clouds, and damaged files, are one clear line and exit 2;
// LiDAR names never collide into an error.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bag_dataset.hpp"
#include "run_command.hpp"
#include "test_paths.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/result_file.hpp"
#include "ulc/io/sequence.hpp"
#include "ulc_app_path.hpp"

namespace fs = std::filesystem;
using ulc_test::kUlc;
using ulc_test::quote;
using ulc_test::run_command;

namespace {

/// A 0.6 s 64-32 drive and the same drive as every kind of recording, removed afterwards.
struct BagDrive {
  fs::path dir;
  BagDrive() : dir(fs::temp_directory_path() / "ulc_test_cli_bags") {
    fs::remove_all(dir);
    const auto run = run_command(kUlc + " simulate --quiet --scenario 64-32 --seconds 0.6 " +
                                 "--seed 3 --out " + quote((dir / "folders").string()));
    INFO(run.output);
    REQUIRE(run.exit_code == 0);
    using ulc::bags::Codec;
    using ulc::bags::RecordingKind;
    ulc_test::write_dataset_as_recording(dir / "folders", dir / "drive.bag",
                                         {RecordingKind::ros1_bag, Codec::lz4, true});
    ulc_test::write_dataset_as_recording(dir / "folders", dir / "drive.mcap",
                                         {RecordingKind::mcap, Codec::zstd, true});
    ulc_test::write_dataset_as_recording(dir / "folders", dir / "rosbag2",
                                         {RecordingKind::rosbag2_sqlite, Codec::none, true});
  }
  ~BagDrive() { fs::remove_all(dir); }
  std::string path(const std::string& name) const { return (dir / name).string(); }
};

const BagDrive& drive() {
  static const BagDrive d;
  return d;
}

ulc::io::PairResult calibrate(const std::string& base, const std::string& target,
                              const std::string& out) {
  const auto run =
      run_command(kUlc + " calibrate --quiet --stages terra,jeep --base " + quote(base) +
                  " --target " + quote(target) + " --output " + quote(out));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  const auto r = ulc::io::read_result_file(out);
  REQUIRE(r.size() == 1);
  return r[0];
}

}  // namespace

TEST_CASE("a rig calibrates from a ROS 1 bag, MCAP and rosbag2 as from its folders",
          "[app][bags]") {
  const BagDrive& d = drive();
  const auto folders =
      calibrate(d.path("folders/lidar64"), d.path("folders/lidar32"), d.path("folders.json"));
  for (const char* recording : {"drive.bag", "drive.mcap", "rosbag2"}) {
    CAPTURE(recording);
    const std::string rec = d.path(recording);
    const auto r = calibrate(rec + ":/lidar64/points", rec + ":/lidar32/points",
                             d.path(std::string(recording) + ".json"));
    // Named by the messages' frame_id, as the folders are named.
    CHECK(r.base == "lidar64");
    CHECK(r.target == "lidar32");
    const auto e = ulc::pose_error(folders.T_base_target, r.T_base_target);
    CHECK(e.rotation_deg < 1e-4);
    CHECK(e.translation_m < 1e-5);
  }
}

TEST_CASE("ulc export writes a recording's topic back as the frames it came from", "[app][bags]") {
  const BagDrive& d = drive();
  const std::string out = d.path("exported");
  const auto run =
      run_command(kUlc + " export " + quote(d.path("drive.mcap") + ":/lidar32/points") + " " +
                  quote(d.path("drive.bag") + ":/lidar64/points=top") + " " + quote(out));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  const ulc::io::Sequence original(d.path("folders/lidar32")), exported(out + "/lidar32");
  REQUIRE(exported.size() == original.size());
  REQUIRE(exported.time_source() == ulc::io::FrameTimeSource::timestamps_file);
  for (std::size_t i = 0; i < original.size(); ++i) {
    CHECK(std::abs(exported.frame(i).timestamp - original.frame(i).timestamp) < 1e-9);
    const auto a = original.load_decoded(i), b = exported.load_decoded(i);
    REQUIRE(a.size() == b.size());
    CHECK(a.points == b.points);
    CHECK(a.times == b.times);
  }
  CHECK(ulc::io::Sequence(out + "/top").size() ==
        ulc::io::Sequence(d.path("folders/lidar64")).size());

  // --start / --duration: frames from 0.2 s after the first message, for 0.3 s.
  const auto part =
      run_command(kUlc + " export --start 0.2 --duration 0.3 " +
                  quote(d.path("drive.bag") + ":/lidar32/points") + " " + quote(d.path("part")));
  INFO(part.output);
  REQUIRE(part.exit_code == 0);
  CHECK(ulc::io::Sequence(d.path("part/lidar32")).size() == 3);
}

TEST_CASE("ulc inspect lists a recording's topics and describes a cloud topic", "[app][bags]") {
  const BagDrive& d = drive();
  for (const char* recording : {"drive.bag", "drive.mcap", "rosbag2"}) {
    const auto run = run_command(kUlc + " inspect " + quote(d.path(recording)));
    INFO(run.output);
    REQUIRE(run.exit_code == 0);
    CHECK_THAT(run.output, Catch::Contains("/lidar64/points") && Catch::Contains("PointCloud2") &&
                               Catch::Contains("point cloud"));
  }
  const auto run = run_command(
      kUlc + " inspect " + quote(d.path("drive.bag") + ":/lidar32/points") + " --frame-index 2");
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  CHECK_THAT(run.output, Catch::Contains("frame_id 'lidar32'") &&
                             Catch::Contains("`time` float32 seconds relative to header.stamp"));
}

TEST_CASE("missing topics, non-cloud topics and damaged recordings: one line, exit 2",
          "[app][bags]") {
  const BagDrive& d = drive();
  const std::string bag = d.path("drive.bag");
  auto run = run_command(kUlc + " calibrate --base " + quote(bag + ":/nope") + " --target " +
                         quote(bag + ":/lidar32/points"));
  CHECK(run.exit_code == 2);
  CHECK_THAT(run.output, Catch::Contains("no topic '/nope'") && Catch::Contains("/lidar64/points"));
  // A recording with several cloud topics needs one named.
  run = run_command(kUlc + " export " + quote(bag) + " " + quote(d.path("x")));
  CHECK(run.exit_code == 2);
  CHECK_THAT(run.output, Catch::Contains("name the LiDAR's topic"));

  // Cut in the middle of a chunk: the file, a byte offset and the problem.
  const std::string cut = d.path("cut.bag");
  {
    std::ifstream in(bag, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream out(cut, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  run = run_command(kUlc + " export " + quote(cut + ":/lidar64/points") + " " + quote(d.path("y")));
  INFO(run.output);
  CHECK(run.exit_code == 2);
  CHECK_THAT(run.output, Catch::Contains(cut) && Catch::Contains("byte "));
}

TEST_CASE("real bags: ulc inspect lists every topic, type and count", "[app][bags]") {
  const auto dir = ulc_test::bags_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags not found next to the checkout");
  auto run = run_command(kUlc + " inspect " + quote((dir / "ros1/example.bag").string()));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  for (const auto& [topic, count] :
       std::vector<std::pair<std::string, int>>{{"/turtle1/color_sensor", 1351},
                                                {"/turtle2/color_sensor", 1344},
                                                {"/turtle1/pose", 1344},
                                                {"/turtle2/pose", 1344},
                                                {"/tf", 2688},
                                                {"/rosout", 10},
                                                {"/tf_static", 1},
                                                {"/turtle1/cmd_vel", 357},
                                                {"/turtle2/cmd_vel", 208}}) {
    CAPTURE(topic);
    const auto at = run.output.find("  " + topic + " ");
    REQUIRE(at != std::string::npos);
    const std::string line = run.output.substr(at, run.output.find('\n', at) - at);
    CHECK_THAT(line, Catch::Contains(" " + std::to_string(count) + " msgs"));
  }
  CHECK_THAT(run.output, Catch::Contains("point-cloud topics: none"));

  run = run_command(kUlc + " inspect " + quote((dir / "ros2/mcap/talker").string()));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  CHECK_THAT(run.output,
             Catch::Contains("std_msgs/msg/String") && Catch::Contains("/parameter_events"));

  run = run_command(kUlc + " inspect " + quote((dir / "ros1/empty-file.bag").string()));
  CHECK(run.exit_code == 2);
  CHECK_THAT(run.output, Catch::Contains("empty-file.bag") && Catch::Contains("empty"));
}

TEST_CASE("LiDAR names: repeated stems take their folder, =NAME names explicitly", "[app][bags]") {
  const BagDrive& d = drive();
  const fs::path root = d.dir / "names";
  fs::create_directories(root / "sensor_1");
  fs::create_directories(root / "sensor_2");
  fs::copy_file(d.dir / "folders/lidar64/000000.pcd", root / "sensor_1/1.pcd");
  fs::copy_file(d.dir / "folders/lidar32/000000.pcd", root / "sensor_2/1.pcd");
  const std::string a = (root / "sensor_1/1.pcd").string(), b = (root / "sensor_2/1.pcd").string();
  auto run = run_command(kUlc + " calibrate --quiet --stages terra --base " + quote(a) +
                         " --target " + quote(b));
  INFO(run.output);
  CHECK(run.exit_code != 2);
  CHECK_THAT(run.output, Catch::Contains("sensor_1/1 <- sensor_2/1"));
  run = run_command(kUlc + " calibrate --quiet --stages terra --base " + quote(a + "=top") +
                    " --target " + quote(b + "=left"));
  INFO(run.output);
  CHECK_THAT(run.output, Catch::Contains("top <- left"));
  run = run_command(kUlc + " calibrate --quiet --stages terra --base " + quote(a + "=same") +
                    " --target " + quote(b + "=same"));
  CHECK(run.exit_code == 2);
  CHECK_THAT(run.output, Catch::Contains("two LiDARs are named 'same'"));
}
