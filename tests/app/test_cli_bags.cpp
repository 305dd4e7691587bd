// `ulc` on recordings: a simulated rig written as a ROS 1 bag, an MCAP file and a rosbag2 folder
// calibrates to the same extrinsic as from its frame folders; `ulc inspect` lists the topics of
// bags other tools wrote exactly as their README says; `ulc export` writes the frames back;
// topics that are missing or not clouds, and damaged files, are one clear line and exit 2;
// LiDAR names never collide into an error.
#include <unistd.h>
#include <algorithm>

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
  // One folder per process: CTest runs the test cases as parallel processes.
  BagDrive()
      : dir(fs::temp_directory_path() / ("ulc_test_cli_bags_" + std::to_string(::getpid()))) {
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
      run_command(kUlc + " calibrate --quiet --synced-clocks --stages terra,jeep --base " +
                  quote(base) + " --target " + quote(target) + " --output " + quote(out));
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
  // The same window over the frame folder.
  const auto folder =
      run_command(kUlc + " export --start 0.2 --duration 0.3 " + quote(d.path("folders/lidar32")) +
                  " " + quote(d.path("part_folder")));
  INFO(folder.output);
  REQUIRE(folder.exit_code == 0);
  const ulc::io::Sequence from_bag(d.path("part/lidar32")),
      from_folder(d.path("part_folder/lidar32"));
  REQUIRE(from_folder.size() == 3);
  for (std::size_t i = 0; i < 3; ++i)
    CHECK(std::abs(from_folder.frame(i).timestamp - from_bag.frame(i).timestamp) < 1e-9);
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

namespace {

struct TopicLine {
  std::string topic, type;
  int count;
};

/// `ulc inspect FILE` lists each topic on its own line with its type and message count.
void expect_topics(const std::filesystem::path& file, const std::vector<TopicLine>& topics,
                   std::size_t total_topics) {
  const auto run = run_command(kUlc + " inspect " + quote(file.string()));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  CHECK_THAT(run.output, Catch::Contains(": " + std::to_string(total_topics) + " topic"));
  for (const auto& t : topics) {
    CAPTURE(t.topic);
    const auto at = run.output.find("  " + t.topic + " ");
    REQUIRE(at != std::string::npos);
    const std::string line = run.output.substr(at, run.output.find('\n', at) - at);
    CHECK_THAT(line, Catch::Contains(" " + t.type + " ") &&
                         Catch::Contains(" " + std::to_string(t.count) + " msgs"));
  }
  CHECK_THAT(run.output, Catch::Contains("point-cloud topics: none"));
}

}  // namespace

TEST_CASE("real bags: ulc inspect lists every topic, type and count", "[app][bags]") {
  const auto dir = ulc_test::bags_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags not found next to the checkout");
  const std::vector<TopicLine> turtles = {{"/turtle1/color_sensor", "turtlesim/Color", 1351},
                                          {"/turtle2/color_sensor", "turtlesim/Color", 1344},
                                          {"/turtle1/pose", "turtlesim/Pose", 1344},
                                          {"/turtle2/pose", "turtlesim/Pose", 1344},
                                          {"/tf", "tf/tfMessage", 2688},
                                          {"/rosout", "rosgraph_msgs/Log", 10},
                                          {"/tf_static", "tf2_msgs/TFMessage", 1},
                                          {"/turtle1/cmd_vel", "geometry_msgs/Twist", 357},
                                          {"/turtle2/cmd_vel", "geometry_msgs/Twist", 208}};
  for (const char* f : {"example.bag", "example-bz2.bag", "example-lz4.bag"})
    expect_topics(dir / "ros1" / f, turtles, 9);
  expect_topics(dir / "ros1/example-unsorted-chunks.bag", {{"foo", "std_msgs/String", 3}}, 1);
  expect_topics(dir / "ros1/no-messages.bag", {}, 0);
  for (const char* storage : {"mcap", "sqlite3"}) {
    CAPTURE(storage);
    const auto root = dir / "ros2" / storage;
    expect_topics(root / "talker",
                  {{"/topic", "std_msgs/msg/String", 10},
                   {"/rosout", "rcl_interfaces/msg/Log", 10},
                   {"/parameter_events", "rcl_interfaces/msg/ParameterEvent", 0}},
                  3);
    expect_topics(root / "wbag",
                  {{"AAA", "std_msgs/msg/String", 804},
                   {"BBB", "std_msgs/msg/String", 742},
                   {"CCC", "std_msgs/msg/String", 742},
                   {"DDD", "std_msgs/msg/String", 753},
                   {"EEE", "std_msgs/msg/String", 804},
                   {"FFF", "std_msgs/msg/String", 772},
                   {"GGG", "std_msgs/msg/String", 731},
                   {"HHH", "std_msgs/msg/String", 726}},
                  8);
    expect_topics(
        root / "convert_a",
        {{"a_empty", "test_msgs/msg/Empty", 100}, {"b_basictypes", "test_msgs/msg/BasicTypes", 50}},
        2);
    expect_topics(root / "cdr_test",
                  {{"/test_topic", "test_msgs/msg/BasicTypes", 3},
                   {"/array_topic", "test_msgs/msg/Arrays", 4}},
                  2);
  }
  const auto run = run_command(kUlc + " inspect " + quote((dir / "ros1/empty-file.bag").string()));
  CHECK(run.exit_code == 2);
  CHECK_THAT(run.output, Catch::Contains("empty-file.bag") && Catch::Contains("empty"));
  CHECK(std::count(run.output.begin(), run.output.end(), '\n') == 1);
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
