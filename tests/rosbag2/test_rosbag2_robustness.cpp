// Damaged .db3 files and metadata.yaml: an io::IoError naming the file, never anything else.
#include <catch2/catch.hpp>
#include <fstream>
#include <iterator>

#include "rosbag2_test_util.hpp"
#include "ulc/bags/rosbag2_folder.hpp"
#include "ulc/bags/rosbag2_sqlite.hpp"
#include "ulc/bags/rosbag2_sqlite_writer.hpp"

namespace robustness_test {

using namespace ulc::bags;

inline std::vector<char> file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}

inline void save(const std::filesystem::path& path, const char* data, std::size_t n) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data, static_cast<std::streamsize>(n));
}

inline void save(const std::filesystem::path& path, const std::string& text) {
  save(path, text.data(), text.size());
}

/// A small bag: 3 topics, 40 messages of up to 600 bytes (a few 4 KiB pages).
inline std::vector<char> small_bag(const std::filesystem::path& path) {
  {
    Rosbag2SqliteWriter writer(path);
    const auto a = writer.add_topic("/a", "std_msgs/msg/String");
    const auto b = writer.add_topic("/b", "sensor_msgs/msg/Imu");
    writer.add_topic("/c", "std_msgs/msg/Empty");
    for (int i = 0; i < 40; ++i) {
      const std::vector<unsigned char> data(static_cast<std::size_t>(i * 15),
                                            static_cast<unsigned char>(i));
      writer.write(i % 2 == 0 ? a : b, 1000 - i * 7, data.data(), data.size());
    }
  }
  return file_bytes(path);
}

enum class Outcome { read, io_error };

/// Opens and reads everything; an IoError must name the file.
inline Outcome open_and_read(const std::filesystem::path& path) {
  try {
    const Rosbag2Sqlite bag(path);
    std::size_t n = 0;
    bag.read(rosbag2_test::all_topics(bag), {}, [&](const MessageView& m) {
      n += m.size;
      return true;
    });
    return Outcome::read;
  } catch (const ulc::io::IoError& e) {
    REQUIRE(e.file() == path.string());
    REQUIRE_FALSE(e.reason().empty());
    return Outcome::io_error;
  }
}

TEST_CASE("rosbag2 sqlite: a file cut anywhere is read or an IoError", "[rosbag2][robustness]") {
  rosbag2_test::TempDir dir("cut");
  const auto bytes = small_bag(dir.path() / "whole.db3");
  REQUIRE(bytes.size() >= 4096 * 3);
  const auto cut = dir.path() / "cut.db3";
  std::size_t errors = 0, cuts = 0;
  for (std::size_t n = 0; n < bytes.size(); n += (n < 200 ? 1 : 61)) {
    save(cut, bytes.data(), n);
    errors += open_and_read(cut) == Outcome::io_error ? 1 : 0;
    ++cuts;
  }
  CHECK(errors > cuts / 2);
  save(cut, bytes.data(), bytes.size());
  CHECK(open_and_read(cut) == Outcome::read);
}

TEST_CASE("rosbag2 sqlite: flipped bytes are read or an IoError", "[rosbag2][robustness]") {
  rosbag2_test::TempDir dir("flip");
  const auto bytes = small_bag(dir.path() / "whole.db3");
  const auto flipped = dir.path() / "flipped.db3";
  std::size_t errors = 0;
  for (std::size_t at = 0; at < bytes.size(); at += (at < 120 ? 1 : 37)) {
    for (const unsigned char mask : {0x01, 0xff}) {
      auto copy = bytes;
      copy[at] = static_cast<char>(static_cast<unsigned char>(copy[at]) ^ mask);
      save(flipped, copy.data(), copy.size());
      errors += open_and_read(flipped) == Outcome::io_error ? 1 : 0;
    }
  }
  CHECK(errors > 0);
}

/// Opening `path` must fail with an IoError naming it and saying `words`.
inline void check_open_error(const std::filesystem::path& path, const std::string& words) {
  try {
    const Rosbag2Sqlite bag(path);
    FAIL("opened " << path);
  } catch (const ulc::io::IoError& e) {
    CHECK(e.file() == path.string());
    CHECK_THAT(e.what(), Catch::Contains(words));
  }
}

TEST_CASE("rosbag2 sqlite: files that are not bags", "[rosbag2][robustness]") {
  rosbag2_test::TempDir dir("not_bags");
  save(dir.path() / "empty.db3", std::string());
  check_open_error(dir.path() / "empty.db3", "0 bytes");
  save(dir.path() / "text.db3", "rosbag2_bagfile_information:\n  version: 4\n");
  check_open_error(dir.path() / "text.db3", "not a SQLite database");
  save(dir.path() / "short.db3", std::string("SQLite format 3\0abc", 19));
  check_open_error(dir.path() / "short.db3", "truncated");
  check_open_error(dir.path() / "missing.db3", "no such file");
  check_open_error(dir.path(), "folder");
  // A SQLite database without rosbag2's tables.
  {
    sqlite3* db = nullptr;
    REQUIRE(sqlite3_open((dir.path() / "other.db3").string().c_str(), &db) == SQLITE_OK);
    REQUIRE(sqlite3_exec(db, "CREATE TABLE t(x)", nullptr, nullptr, nullptr) == SQLITE_OK);
    sqlite3_close(db);
  }
  check_open_error(dir.path() / "other.db3", "no such table");
}

/// A .db3 file made by hand: a topics table without a primary key (so ids may repeat or be
/// anything) holding `topic_rows`, rosbag2's messages table, and one message on topic id 1.
inline std::filesystem::path hand_made_bag(const rosbag2_test::TempDir& dir,
                                           const std::string& name, const std::string& topic_rows) {
  const auto path = dir.path() / name;
  sqlite3* db = nullptr;
  REQUIRE(sqlite3_open(path.string().c_str(), &db) == SQLITE_OK);
  const std::string sql =
      "CREATE TABLE topics(id, name TEXT, type TEXT, serialization_format TEXT);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, "
      "data BLOB);"
      "INSERT INTO messages VALUES (1, 1, 100, x'00');" +
      topic_rows;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr);
  sqlite3_close(db);
  REQUIRE(rc == SQLITE_OK);
  return path;
}

TEST_CASE("rosbag2 sqlite: a topic id listed twice or not an integer is an IoError",
          "[rosbag2][robustness]") {
  rosbag2_test::TempDir dir("topic_ids");
  // Two names on one id: a cursor on the first would hand out messages as the second's.
  check_open_error(
      hand_made_bag(dir, "two_names.db3",
                    "INSERT INTO topics VALUES (1, '/a', 'std_msgs/msg/String', 'cdr');"
                    "INSERT INTO topics VALUES (1, '/b', 'std_msgs/msg/String', 'cdr');"),
      "topic id 1 is listed twice");
  check_open_error(
      hand_made_bag(dir, "same_row_twice.db3",
                    "INSERT INTO topics VALUES (1, '/a', 'std_msgs/msg/String', 'cdr');"
                    "INSERT INTO topics VALUES (1, '/a', 'std_msgs/msg/String', 'cdr');"),
      "topic id 1 is listed twice");
  int file = 0;
  for (const std::string id : {"1.5", "'1'", "NULL", "x'01'"})
    check_open_error(hand_made_bag(dir, "id_" + std::to_string(file++) + ".db3",
                                   "INSERT INTO topics VALUES (" + id +
                                       ", '/a', 'std_msgs/msg/String', 'cdr');"),
                     "not an integer");
  // The same table with distinct integer ids reads.
  const Rosbag2Sqlite good(
      hand_made_bag(dir, "good.db3",
                    "INSERT INTO topics VALUES (1, '/a', 'std_msgs/msg/String', 'cdr');"
                    "INSERT INTO topics VALUES (2, '/b', 'std_msgs/msg/String', 'cdr');"));
  REQUIRE(good.topics().size() == 2);
  CHECK(rosbag2_test::read_all(good, {0}).size() == 1);
  CHECK(rosbag2_test::read_all(good, {1}).empty());
}

/// A bag folder holding one written .db3 file and the given metadata.yaml text.
inline std::filesystem::path folder_with_metadata(const rosbag2_test::TempDir& dir,
                                                  const std::string& name,
                                                  const std::string& yaml) {
  const auto folder = dir.path() / name;
  std::filesystem::create_directories(folder);
  small_bag(folder / "bag_0.db3");
  save(folder / "metadata.yaml", yaml);
  return folder;
}

inline void check_metadata_error(const std::filesystem::path& folder, const std::string& words,
                                 bool with_line) {
  try {
    rosbag2_files(folder);
    FAIL("accepted " << folder);
  } catch (const ulc::io::IoError& e) {
    CHECK(e.file() == (folder / "metadata.yaml").string());
    CHECK_THAT(e.reason(), Catch::Contains(words));
    if (with_line) CHECK_THAT(e.position(), Catch::StartsWith("line "));
  }
}

TEST_CASE("rosbag2 folder: bad metadata.yaml is an IoError naming it", "[rosbag2][robustness]") {
  rosbag2_test::TempDir dir("metadata");
  check_metadata_error(
      folder_with_metadata(dir, "not_yaml", "rosbag2_bagfile_information:\n  version: [4\n  x: {"),
      "YAML", true);
  check_metadata_error(folder_with_metadata(dir, "no_info", "something_else:\n  version: 4\n"),
                       "rosbag2_bagfile_information", false);
  check_metadata_error(folder_with_metadata(dir, "empty", ""), "rosbag2_bagfile_information",
                       false);
  check_metadata_error(
      folder_with_metadata(dir, "no_paths", "rosbag2_bagfile_information:\n  version: 4\n"),
      "relative_file_paths", false);
  check_metadata_error(folder_with_metadata(dir, "paths_not_list",
                                            "rosbag2_bagfile_information:\n  "
                                            "relative_file_paths: {a: 1}\n"),
                       "relative_file_paths", true);
  check_metadata_error(folder_with_metadata(dir, "missing_file",
                                            "rosbag2_bagfile_information:\n"
                                            "  storage_identifier: sqlite3\n"
                                            "  relative_file_paths:\n"
                                            "    - bag_0.db3\n"
                                            "    - bag_1.db3\n"),
                       "bag_1.db3", true);
  check_metadata_error(folder_with_metadata(dir, "compressed",
                                            "rosbag2_bagfile_information:\n"
                                            "  compression_mode: FILE\n"
                                            "  compression_format: zstd\n"
                                            "  relative_file_paths:\n"
                                            "    - bag_0.db3.zstd\n"),
                       "compress", false);
}

TEST_CASE("rosbag2 folder: old relative paths, with the folder or without the extension",
          "[rosbag2]") {
  rosbag2_test::TempDir dir("old_paths");
  const auto with_folder = folder_with_metadata(dir, "old_bag",
                                                "rosbag2_bagfile_information:\n"
                                                "  version: 3\n"
                                                "  storage_identifier: sqlite3\n"
                                                "  relative_file_paths:\n"
                                                "    - old_bag/bag_0.db3\n");
  CHECK(rosbag2_files(with_folder) ==
        std::vector<std::filesystem::path>{with_folder / "bag_0.db3"});
  const auto no_extension = folder_with_metadata(dir, "bare",
                                                 "rosbag2_bagfile_information:\n"
                                                 "  storage_identifier: sqlite3\n"
                                                 "  relative_file_paths: [bag_0]\n");
  CHECK(rosbag2_files(no_extension) ==
        std::vector<std::filesystem::path>{no_extension / "bag_0.db3"});
}

TEST_CASE("rosbag2 folder: without metadata.yaml, files in natural order", "[rosbag2]") {
  rosbag2_test::TempDir dir("no_metadata");
  const auto folder = dir.path() / "rec";
  std::filesystem::create_directories(folder);
  for (const char* name :
       {"wbag_10.db3", "wbag_2.db3", "wbag_1.db3", "wbag_0.mcap", "notes.txt", "wbag_002.db3"})
    save(folder / name, std::string("x"));
  CHECK(rosbag2_files(folder) ==
        std::vector<std::filesystem::path>{folder / "wbag_0.mcap", folder / "wbag_1.db3",
                                           folder / "wbag_002.db3", folder / "wbag_2.db3",
                                           folder / "wbag_10.db3"});
  std::filesystem::create_directories(dir.path() / "empty");
  CHECK_THROWS_AS(rosbag2_files(dir.path() / "empty"), ulc::io::IoError);
  CHECK_THROWS_AS(rosbag2_files(dir.path() / "absent"), ulc::io::IoError);
  CHECK_THROWS_AS(rosbag2_files(folder / "notes.txt"), ulc::io::IoError);
}

TEST_CASE("rosbag2 folder: written split folder without its metadata.yaml", "[rosbag2]") {
  rosbag2_test::TempDir dir("split_no_metadata");
  const auto folder = dir.path() / "b";
  std::size_t written = 0;
  {
    Rosbag2SqliteWriter writer(folder, 2000);
    const auto t = writer.add_topic("/t", "std_msgs/msg/String");
    const std::vector<unsigned char> data(300, 9);
    for (int i = 0; i < 150; ++i, ++written)
      writer.write(t, (i * 37) % 101, data.data(), data.size());
  }
  std::filesystem::remove(folder / "metadata.yaml");
  const auto bag = open_rosbag2_folder(
      folder, [](const std::filesystem::path& p) { return std::make_unique<Rosbag2Sqlite>(p); });
  REQUIRE(rosbag2_files(folder).size() > 10);  // b_10.db3 must come after b_9.db3
  const auto messages = rosbag2_test::read_all(*bag, {0});
  REQUIRE(messages.size() == written);
  for (std::size_t i = 1; i < messages.size(); ++i)
    REQUIRE(messages[i - 1].time_ns <= messages[i].time_ns);
}

}  // namespace robustness_test
