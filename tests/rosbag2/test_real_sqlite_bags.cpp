// The real rosbag2 bags of ../shared/data/bags/ros2 (README there): every topic, type and count.
#include <catch2/catch.hpp>
#include <map>

#include "rosbag2_test_util.hpp"
#include "test_paths.hpp"
#include "ulc/bags/rosbag2_folder.hpp"
#include "ulc/bags/rosbag2_sqlite.hpp"

namespace real_sqlite_test {

using namespace ulc::bags;

struct Expected {
  std::string name, type;
  std::uint64_t count;
};

inline std::filesystem::path ros2_dir() {
  const auto bags = ulc_test::bags_dir();
  return bags.empty() ? bags : bags / "ros2";
}

inline std::unique_ptr<MessageSource> open_sqlite_folder(const std::filesystem::path& folder) {
  return open_rosbag2_folder(
      folder, [](const std::filesystem::path& p) { return std::make_unique<Rosbag2Sqlite>(p); });
}

/// Topics exactly as expected (sorted by name), and a full read that matches the counts, in time
/// order, each message inside its topic's [first, last].
inline void check_bag(const MessageSource& bag, const std::vector<Expected>& expected) {
  const auto& topics = bag.topics();
  REQUIRE(topics.size() == expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    INFO(expected[i].name);
    CHECK(topics[i].name == expected[i].name);
    CHECK(topics[i].type == expected[i].type);
    CHECK(topics[i].serialization == Serialization::cdr);
    CHECK(topics[i].message_count == expected[i].count);
  }
  std::vector<std::uint64_t> seen(topics.size(), 0);
  std::int64_t previous = std::numeric_limits<std::int64_t>::min();
  bool ordered = true, inside = true;
  bag.read(rosbag2_test::all_topics(bag), {}, [&](const MessageView& m) {
    ordered = ordered && m.time_ns >= previous;
    previous = m.time_ns;
    const TopicInfo& t = topics[m.topic];
    inside = inside && m.time_ns >= t.first_time_ns && m.time_ns <= t.last_time_ns;
    ++seen[m.topic];
    return true;
  });
  CHECK(ordered);
  CHECK(inside);
  for (std::size_t i = 0; i < topics.size(); ++i) CHECK(seen[i] == topics[i].message_count);
}

TEST_CASE("rosbag2 real sqlite: talker (WAL mode, -shm beside it)", "[rosbag2][real]") {
  const auto dir = ros2_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  const auto folder = dir / "sqlite3" / "talker";
  const std::vector<Expected> expected{
      {"/parameter_events", "rcl_interfaces/msg/ParameterEvent", 0},
      {"/rosout", "rcl_interfaces/msg/Log", 10},
      {"/topic", "std_msgs/msg/String", 10}};
  REQUIRE(rosbag2_files(folder) == std::vector<std::filesystem::path>{folder / "talker.db3"});
  const auto bag = open_sqlite_folder(folder);
  check_bag(*bag, expected);
  CHECK(bag->topics()[0].first_time_ns == 0);
  CHECK(bag->topics()[2].first_time_ns == 1585866235112609068);
  CHECK(bag->topics()[2].last_time_ns == 1585866239643508139);
  // The first /topic message: CDR std_msgs/String "Hello, world! 0".
  const auto messages = rosbag2_test::read_all(*bag, {2});
  REQUIRE(messages.size() == 10);
  const std::string text(messages[0].data.begin() + 8, messages[0].data.end() - 1);
  CHECK(text == "Hello, world! 0");
  CHECK(bag->warnings().empty());
}

TEST_CASE("rosbag2 real sqlite: wbag, split over 5 files", "[rosbag2][real]") {
  const auto dir = ros2_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  const auto folder = dir / "sqlite3" / "wbag";
  const auto files = rosbag2_files(folder);
  REQUIRE(files.size() == 5);
  for (std::size_t i = 0; i < 5; ++i)
    CHECK(files[i] == folder / ("wbag_" + std::to_string(i) + ".db3"));
  const std::string s = "std_msgs/msg/String";
  const auto bag = open_sqlite_folder(folder);
  check_bag(*bag, {{"AAA", s, 804},
                   {"BBB", s, 742},
                   {"CCC", s, 742},
                   {"DDD", s, 753},
                   {"EEE", s, 804},
                   {"FFF", s, 772},
                   {"GGG", s, 731},
                   {"HHH", s, 726}});
  std::uint64_t total = 0;
  std::int64_t first = std::numeric_limits<std::int64_t>::max(), last = 0;
  for (const auto& t : bag->topics()) {
    total += t.message_count;
    first = std::min(first, t.first_time_ns);
    last = std::max(last, t.last_time_ns);
    CHECK(t.connections == 1);  // one per file: a split bag does not add connections
  }
  CHECK(total == 6074);
  CHECK(first == 1000);
  CHECK(last == 2998);
  // A window and one topic.
  const auto window = rosbag2_test::read_all(*bag, {0}, TimeWindow{1400, 1500});
  CHECK_FALSE(window.empty());
  for (const auto& m : window) CHECK((m.time_ns >= 1400 && m.time_ns < 1500 && m.topic == "AAA"));
}

TEST_CASE("rosbag2 real sqlite: convert_a and cdr_test", "[rosbag2][real]") {
  const auto dir = ros2_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  const auto convert = open_sqlite_folder(dir / "sqlite3" / "convert_a");
  check_bag(*convert, {{"a_empty", "test_msgs/msg/Empty", 100},
                       {"b_basictypes", "test_msgs/msg/BasicTypes", 50}});
  const auto cdr = open_sqlite_folder(dir / "sqlite3" / "cdr_test");
  check_bag(*cdr, {{"/array_topic", "test_msgs/msg/Arrays", 4},
                   {"/test_topic", "test_msgs/msg/BasicTypes", 3}});
  std::size_t bytes = 0;
  for (const auto& m : rosbag2_test::read_all(*cdr, {0})) bytes += m.data.size();
  CHECK(bytes == 4 * 696);
  // The file alone, without its folder.
  const Rosbag2Sqlite file(dir / "sqlite3" / "cdr_test" / "cdr_test_0.db3");
  CHECK(file.topics().size() == 2);
}

TEST_CASE("rosbag2 real mcap folders: the file lists of metadata.yaml", "[rosbag2][real]") {
  const auto dir = ros2_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "../shared/data/bags is absent");
  const auto mcap = dir / "mcap";
  CHECK(rosbag2_files(mcap / "talker") ==
        std::vector<std::filesystem::path>{mcap / "talker" / "talker.mcap"});
  CHECK(rosbag2_files(mcap / "convert_a") ==
        std::vector<std::filesystem::path>{mcap / "convert_a" / "rewriter_a_0.mcap"});
  CHECK(rosbag2_files(mcap / "cdr_test") ==
        std::vector<std::filesystem::path>{mcap / "cdr_test" / "cdr_test_0.mcap"});
  std::vector<std::filesystem::path> wbag;
  for (int i = 0; i < 5; ++i)
    wbag.push_back(mcap / "wbag" / ("wbag_" + std::to_string(i) + ".mcap"));
  CHECK(rosbag2_files(mcap / "wbag") == wbag);
  CHECK(read_rosbag2_metadata(mcap / "wbag").storage_identifier == "mcap");
  CHECK(read_rosbag2_metadata(dir / "sqlite3" / "wbag").storage_identifier == "sqlite3");
}

}  // namespace real_sqlite_test
