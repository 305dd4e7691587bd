// Ros1Bag on bags recorded by rosbag itself (../shared/data/bags/ros1, from rosbag.js's
// fixtures): topics, types and counts as ../shared/data/bags/README.md states them.
#include <catch2/catch.hpp>
#include <map>

#include "ros1_test_util.hpp"
#include "test_paths.hpp"

namespace ros1_real_files {

using namespace ros1_test;
using ulc::bags::Ros1Bag;

inline fs::path ros1_dir() {
  const auto bags = ulc_test::bags_dir();
  return bags.empty() ? fs::path() : bags / "ros1";
}

struct Expected {
  const char* topic;
  const char* type;
  std::uint64_t count;
  std::size_t connections_uncompressed;  ///< example.bag; the compressed files have one each
};

// The README's counts; the types are the ones rosbag recorded (turtlesim demo).
const Expected kTurtlesim[] = {
    {"/rosout", "rosgraph_msgs/Log", 10, 3},
    {"/tf", "tf/tfMessage", 2688, 2},
    {"/tf_static", "tf2_msgs/TFMessage", 1, 1},
    {"/turtle1/cmd_vel", "geometry_msgs/Twist", 357, 1},
    {"/turtle1/color_sensor", "turtlesim/Color", 1351, 1},
    {"/turtle1/pose", "turtlesim/Pose", 1344, 1},
    {"/turtle2/cmd_vel", "geometry_msgs/Twist", 208, 1},
    {"/turtle2/color_sensor", "turtlesim/Color", 1344, 1},
    {"/turtle2/pose", "turtlesim/Pose", 1344, 1},
};

// The README's stamps, rounded to the microsecond there.
constexpr std::int64_t kFirstStamp = 1396293887844784000LL;
constexpr std::int64_t kLastStamp = 1396293909544870100LL;
constexpr std::int64_t kRounding = 1000;

inline void check_turtlesim(const fs::path& file, bool merged_connections) {
  const Ros1Bag bag(file);
  CHECK(bag.indexed());
  CHECK(bag.warnings().empty());
  const auto& topics = bag.topics();
  REQUIRE(topics.size() == std::size(kTurtlesim));
  std::uint64_t total = 0;
  for (std::size_t k = 0; k < topics.size(); ++k) {
    const Expected& e = kTurtlesim[k];
    INFO(e.topic);
    CHECK(topics[k].name == e.topic);
    CHECK(topics[k].type == e.type);
    CHECK(topics[k].message_count == e.count);
    CHECK(topics[k].connections == (merged_connections ? 1 : e.connections_uncompressed));
    CHECK(topics[k].first_time_ns >= kFirstStamp - kRounding);
    CHECK(topics[k].last_time_ns <= kLastStamp + kRounding);
    CHECK(topics[k].first_time_ns <= topics[k].last_time_ns);
    total += e.count;
  }

  const auto messages = read_all(bag);
  REQUIRE(messages.size() == total);
  std::map<std::string, std::uint64_t> counts;
  for (std::size_t k = 0; k < messages.size(); ++k) {
    ++counts[messages[k].topic];
    if (k > 0) CHECK(messages[k - 1].time_ns <= messages[k].time_ns);
  }
  for (const Expected& e : kTurtlesim) CHECK(counts[e.topic] == e.count);
  CHECK(messages.front().time_ns >= kFirstStamp - kRounding);
  CHECK(messages.front().time_ns <= kFirstStamp + kRounding);
  CHECK(messages.back().time_ns >= kLastStamp - kRounding);
  CHECK(messages.back().time_ns <= kLastStamp + kRounding);
}

TEST_CASE("ros1 bag: real example.bag (uncompressed, 12 connections)") {
  const auto dir = ros1_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  check_turtlesim(dir / "example.bag", false);
}

TEST_CASE("ros1 bag: real example-bz2.bag and example-lz4.bag") {
  const auto dir = ros1_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  check_turtlesim(dir / "example-bz2.bag", true);
  check_turtlesim(dir / "example-lz4.bag", true);
}

TEST_CASE("ros1 bag: the compressed copies hold example.bag's messages") {
  const auto dir = ros1_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  auto plain = read_all(Ros1Bag(dir / "example.bag"));
  auto bz2 = read_all(Ros1Bag(dir / "example-bz2.bag"));
  auto lz4 = read_all(Ros1Bag(dir / "example-lz4.bag"));
  std::sort(plain.begin(), plain.end());
  std::sort(bz2.begin(), bz2.end());
  std::sort(lz4.begin(), lz4.end());
  CHECK(plain == bz2);
  CHECK(plain == lz4);
}

TEST_CASE("ros1 bag: real bag with chunks out of time order") {
  const auto dir = ros1_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  const Ros1Bag bag(dir / "example-unsorted-chunks.bag");
  REQUIRE(bag.topics().size() == 1);
  CHECK(bag.topics()[0].name == "foo");
  CHECK(bag.topics()[0].type == "std_msgs/String");
  CHECK(bag.topics()[0].message_count == 3);
  CHECK(bag.topics()[0].first_time_ns == 1000000000);
  CHECK(bag.topics()[0].last_time_ns == 3000000000);
  const auto messages = read_all(bag);
  REQUIRE(messages.size() == 3);
  for (int k = 0; k < 3; ++k) {
    CHECK(messages[k].time_ns == (k + 1) * 1000000000LL);
    // std_msgs/String: u32 length, then the characters "1", "2", "3".
    CHECK(messages[k].data == Bytes{1, 0, 0, 0, static_cast<unsigned char>('1' + k)});
  }
  const auto second = read_messages(bag, {0}, {1500000000, 2500000000});
  REQUIRE(second.size() == 1);
  CHECK(second[0].time_ns == 2000000000);
}

TEST_CASE("ros1 bag: real bag without messages") {
  const auto dir = ros1_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  const Ros1Bag bag(dir / "no-messages.bag");
  CHECK(bag.topics().empty());
  CHECK(bag.warnings().empty());
  CHECK(read_all(bag).empty());
}

TEST_CASE("ros1 bag: an empty file is an IoError naming it") {
  const auto dir = ros1_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  const auto file = dir / "empty-file.bag";
  try {
    Ros1Bag bag(file);
    FAIL("an empty file opened");
  } catch (const ulc::io::IoError& e) {
    check_io_error(e, file);
  }
}

TEST_CASE("ros1 bag: other formats and versions are clear errors") {
  TempDir dir;
  const auto v12 = dir / "v12.bag";
  Bytes b{'#', 'R', 'O', 'S', 'B', 'A', 'G', ' ', 'V', '1', '.', '2', '\n'};
  b.resize(200, 0);
  write_bytes(v12, b);
  CHECK_THROWS_WITH(Ros1Bag(v12), Catch::Contains("version '1.2' is not supported"));
  const auto text = dir / "text.bag";
  write_bytes(text, Bytes(100, 'x'));
  CHECK_THROWS_WITH(Ros1Bag(text), Catch::Contains("not a ROS bag"));
  CHECK_THROWS_AS(Ros1Bag(dir / "missing.bag"), ulc::io::IoError);
}

}  // namespace ros1_real_files
