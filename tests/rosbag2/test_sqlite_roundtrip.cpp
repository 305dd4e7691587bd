// Rosbag2SqliteWriter -> Rosbag2Sqlite / open_rosbag2_folder read back exactly, in time order.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <map>
#include <random>

#include "rosbag2_test_util.hpp"
#include "ulc/bags/rosbag2_folder.hpp"
#include "ulc/bags/rosbag2_sqlite.hpp"
#include "ulc/bags/rosbag2_sqlite_writer.hpp"

namespace roundtrip_test {

using namespace ulc::bags;
using rosbag2_test::Copied;

struct Written {
  std::vector<Copied> messages;  ///< in write order
  std::vector<Copied> sorted;    ///< by time, ties in write order
};

/// Writes topics /a (cdr), /b (ros1), /c (cdr), /unused (no messages): sizes 0 to 200 kB, times
/// out of order with repeats.
inline Written write_sample(Rosbag2SqliteWriter& writer) {
  const std::int64_t a = writer.add_topic("/a", "sensor_msgs/msg/PointCloud2");
  const std::int64_t b = writer.add_topic("/b", "std_msgs/String", "ros1");
  const std::int64_t c = writer.add_topic("/c", "std_msgs/msg/String", "cdr");
  writer.add_topic("/unused", "std_msgs/msg/Empty");
  REQUIRE(writer.add_topic("/a", "sensor_msgs/msg/PointCloud2") == a);
  const std::map<std::int64_t, std::string> names{{a, "/a"}, {b, "/b"}, {c, "/c"}};
  std::mt19937 random(7);
  Written w;
  for (int i = 0; i < 300; ++i) {
    const std::int64_t topic = 1 + static_cast<std::int64_t>(random() % 3);
    const std::int64_t time = 1'000'000'000 + static_cast<std::int64_t>(random() % 200) * 1000;
    std::size_t size = random() % 3000;
    if (i % 17 == 0) size = 0;
    if (i == 50) size = 200'000;  // spills into SQLite overflow pages
    std::vector<unsigned char> data(size);
    for (auto& byte : data) byte = static_cast<unsigned char>(random());
    writer.write(topic, time, data.data(), data.size());
    w.messages.push_back(Copied{names.at(topic), time, std::move(data)});
  }
  writer.write(c, 5, nullptr, 0);  // earliest, empty, null pointer
  w.messages.push_back(Copied{"/c", 5, {}});
  w.sorted = w.messages;
  std::stable_sort(w.sorted.begin(), w.sorted.end(),
                   [](const Copied& x, const Copied& y) { return x.time_ns < y.time_ns; });
  return w;
}

inline std::vector<Copied> only(const std::vector<Copied>& all, const std::string& topic,
                                TimeWindow window = {}) {
  std::vector<Copied> out;
  for (const auto& m : all)
    if ((topic.empty() || m.topic == topic) && window.contains(m.time_ns)) out.push_back(m);
  return out;
}

inline void check_topics(const MessageSource& source, const Written& w) {
  const auto& topics = source.topics();
  REQUIRE(topics.size() == 4);
  CHECK(topics[0].name == "/a");
  CHECK(topics[0].type == "sensor_msgs/msg/PointCloud2");
  CHECK(topics[0].serialization == Serialization::cdr);
  CHECK(topics[1].name == "/b");
  CHECK(topics[1].serialization == Serialization::ros1);
  CHECK(topics[3].name == "/unused");
  CHECK(topics[3].message_count == 0);
  CHECK(topics[3].first_time_ns == 0);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto expected = only(w.sorted, topics[i].name);
    CHECK(topics[i].message_count == expected.size());
    CHECK(topics[i].first_time_ns == expected.front().time_ns);
    CHECK(topics[i].last_time_ns == expected.back().time_ns);
  }
}

inline void check_reads(const MessageSource& source, const Written& w) {
  CHECK(rosbag2_test::read_all(source, rosbag2_test::all_topics(source)) == w.sorted);
  CHECK(rosbag2_test::read_all(source, {rosbag2_test::topic_index(source, "/b")}) ==
        only(w.sorted, "/b"));
  const TimeWindow window{1'000'050'000, 1'000'120'000};
  CHECK(rosbag2_test::read_all(source, {0, 2}, window).size() ==
        only(w.sorted, "/a", window).size() + only(w.sorted, "/c", window).size());
  CHECK(rosbag2_test::read_all(source, rosbag2_test::all_topics(source), window) ==
        only(w.sorted, "", window));
  CHECK(rosbag2_test::read_all(source, {}).empty());
  CHECK(rosbag2_test::read_all(source, {0}, TimeWindow{10, 10}).empty());
  CHECK_THROWS_AS(source.cursor({99}, {}), std::out_of_range);
}

TEST_CASE("rosbag2 sqlite: a .db3 file reads back exactly in time order", "[rosbag2]") {
  rosbag2_test::TempDir dir("roundtrip_file");
  const auto file = dir.path() / "single.db3";
  Written w;
  {
    Rosbag2SqliteWriter writer(file);
    w = write_sample(writer);
  }
  REQUIRE_FALSE(std::filesystem::exists(dir.path() / "metadata.yaml"));
  const Rosbag2Sqlite bag(file);
  check_topics(bag, w);
  check_reads(bag, w);
  CHECK(bag.warnings().empty());
}

TEST_CASE("rosbag2 sqlite: two cursors at once on one file", "[rosbag2]") {
  rosbag2_test::TempDir dir("two_cursors");
  const auto file = dir.path() / "two.db3";
  Written w;
  {
    Rosbag2SqliteWriter writer(file);
    w = write_sample(writer);
  }
  const Rosbag2Sqlite bag(file);
  auto first = bag.cursor(rosbag2_test::all_topics(bag), {});
  auto second = bag.cursor(rosbag2_test::all_topics(bag), {});
  MessageView x, y;
  std::size_t n = 0;
  while (first->next(x)) {
    REQUIRE(second->next(y));
    REQUIRE(x.time_ns == y.time_ns);
    REQUIRE(x.size == y.size);
    CHECK(*x.file == file.string());
    ++n;
  }
  CHECK_FALSE(second->next(y));
  CHECK(n == w.sorted.size());
}

TEST_CASE("rosbag2 sqlite: a bag folder with metadata.yaml", "[rosbag2]") {
  rosbag2_test::TempDir dir("roundtrip_folder");
  const auto folder = dir.path() / "my_bag";
  Written w;
  {
    Rosbag2SqliteWriter writer(folder);
    w = write_sample(writer);
    writer.close();
    writer.close();  // idempotent
  }
  const auto files = rosbag2_files(folder);
  REQUIRE(files.size() == 1);
  CHECK(files[0] == folder / "my_bag_0.db3");
  const auto meta = read_rosbag2_metadata(folder);
  CHECK(meta.storage_identifier == "sqlite3");

  const YAML::Node info =
      YAML::LoadFile((folder / "metadata.yaml").string())["rosbag2_bagfile_information"];
  CHECK(info["message_count"].as<std::size_t>() == w.messages.size());
  CHECK(info["starting_time"]["nanoseconds_since_epoch"].as<std::int64_t>() == 5);
  CHECK(info["duration"]["nanoseconds"].as<std::int64_t>() == w.sorted.back().time_ns - 5);
  CHECK(info["topics_with_message_count"].size() == 4);
  for (const auto& t : info["topics_with_message_count"]) {
    const auto name = t["topic_metadata"]["name"].as<std::string>();
    CHECK(t["message_count"].as<std::size_t>() == only(w.sorted, name).size());
  }

  const auto bag = open_rosbag2_folder(
      folder, [](const std::filesystem::path& p) { return std::make_unique<Rosbag2Sqlite>(p); });
  CHECK(dynamic_cast<const Rosbag2Sqlite*>(bag.get()) != nullptr);  // one file: no merge
  check_topics(*bag, w);
  check_reads(*bag, w);
}

TEST_CASE("rosbag2 sqlite: a split folder reads back as one recording", "[rosbag2]") {
  rosbag2_test::TempDir dir("roundtrip_split");
  const auto folder = dir.path() / "split_bag";
  Written w;
  {
    Rosbag2SqliteWriter writer(folder, 60'000);
    w = write_sample(writer);
  }
  const auto files = rosbag2_files(folder);
  REQUIRE(files.size() >= 5);
  for (std::size_t i = 0; i < files.size(); ++i)
    CHECK(files[i].filename() == "split_bag_" + std::to_string(i) + ".db3");
  const auto bag = open_rosbag2_folder(
      folder, [](const std::filesystem::path& p) { return std::make_unique<Rosbag2Sqlite>(p); });
  CHECK(dynamic_cast<const MergedSource*>(bag.get()) != nullptr);
  check_topics(*bag, w);
  CHECK(bag->topics()[0].connections == 1);
  check_reads(*bag, w);
  // Each message names the file it came from.
  std::size_t from_last_file = 0;
  bag->read(rosbag2_test::all_topics(*bag), {}, [&](const MessageView& m) {
    from_last_file += *m.file == files.back().string() ? 1 : 0;
    return true;
  });
  CHECK(from_last_file > 0);
}

TEST_CASE("rosbag2 sqlite: an unknown serialization format is listed, not read", "[rosbag2]") {
  rosbag2_test::TempDir dir("unknown_format");
  const auto file = dir.path() / "json.db3";
  {
    Rosbag2SqliteWriter writer(file);
    const auto t = writer.add_topic("/j", "some/msg/Json", "json");
    const unsigned char byte = 1;
    writer.write(t, 3, &byte, 1);
    writer.add_topic("/k", "std_msgs/msg/String");
  }
  const Rosbag2Sqlite bag(file);
  REQUIRE(bag.topics().size() == 2);
  CHECK(bag.topics()[0].message_count == 1);
  CHECK_THROWS_AS(bag.cursor({0}, {}), ulc::io::IoError);
  CHECK(rosbag2_test::read_all(bag, {1}).empty());
}

TEST_CASE("rosbag2 sqlite writer: misuse is reported", "[rosbag2]") {
  rosbag2_test::TempDir dir("misuse");
  Rosbag2SqliteWriter writer(dir.path() / "m.db3");
  const auto t = writer.add_topic("/t", "a/msg/B");
  CHECK_THROWS_AS(writer.add_topic("/t", "other/msg/Type"), std::invalid_argument);
  CHECK_THROWS_AS(writer.write(t + 1, 0, nullptr, 0), std::invalid_argument);
  CHECK_THROWS_AS(Rosbag2SqliteWriter(dir.path() / "s.db3", 1000), ulc::io::IoError);
  std::filesystem::create_directories(dir.path() / "full");
  std::ofstream(dir.path() / "full" / "x.txt") << "x";
  CHECK_THROWS_AS(Rosbag2SqliteWriter(dir.path() / "full"), ulc::io::IoError);
  writer.close();
  CHECK_THROWS_AS(writer.write(t, 0, nullptr, 0), std::logic_error);
}

TEST_CASE("rosbag2 sqlite: messages still in a -wal file are read", "[rosbag2]") {
  rosbag2_test::TempDir dir("wal");
  const auto file = dir.path() / "wal.db3";
  {
    Rosbag2SqliteWriter writer(file);
    writer.add_topic("/w", "std_msgs/msg/String");
    const unsigned char byte = 1;
    writer.write(1, 10, &byte, 1);
  }
  // A second connection switches to WAL mode and keeps its commits in the -wal file (no
  // checkpoint while it stays open), as a recorder that has not closed its file yet.
  sqlite3* db = nullptr;
  REQUIRE(sqlite3_open(file.string().c_str(), &db) == SQLITE_OK);
  REQUIRE(sqlite3_exec(db,
                       "PRAGMA journal_mode=WAL; PRAGMA wal_autocheckpoint=0;"
                       "INSERT INTO messages (topic_id, timestamp, data) VALUES (1, 5, x'02');",
                       nullptr, nullptr, nullptr) == SQLITE_OK);
  REQUIRE(std::filesystem::file_size(file.string() + "-wal") > 0);
  {
    const Rosbag2Sqlite bag(file);
    REQUIRE(bag.topics().size() == 1);
    CHECK(bag.topics()[0].message_count == 2);
    const auto messages = rosbag2_test::read_all(bag, {0});
    REQUIRE(messages.size() == 2);
    CHECK(messages[0].data == std::vector<unsigned char>{2});
    CHECK(bag.warnings().empty());
  }
  sqlite3_close(db);
}

TEST_CASE("rosbag2 sqlite: a file without timestamp_idx still reads in time order", "[rosbag2]") {
  rosbag2_test::TempDir dir("no_index");
  const auto file = dir.path() / "no_index.db3";
  Written w;
  {
    Rosbag2SqliteWriter writer(file);
    w = write_sample(writer);
  }
  sqlite3* db = nullptr;
  REQUIRE(sqlite3_open(file.string().c_str(), &db) == SQLITE_OK);
  REQUIRE(sqlite3_exec(db, "DROP INDEX timestamp_idx", nullptr, nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(db);
  const Rosbag2Sqlite bag(file);
  REQUIRE(bag.warnings().size() == 1);
  CHECK_THAT(bag.warnings()[0], Catch::Contains("no timestamp index"));
  check_topics(bag, w);
  check_reads(bag, w);
}

}  // namespace roundtrip_test
