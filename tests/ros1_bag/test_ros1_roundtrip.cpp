// Bags written by Ros1BagWriter read back exactly by Ros1Bag: every codec, with and without an
// index, messages of 0 bytes and larger than a chunk, times out of order across chunks.
#include <catch2/catch.hpp>

#include "ros1_test_util.hpp"
#include "ulc/io/endian.hpp"

namespace ros1_roundtrip {

using namespace ros1_test;
using ulc::bags::Ros1Bag;
using ulc::bags::Ros1BagWriter;
using ulc::bags::TimeWindow;

constexpr std::int64_t kBase = 1700000000LL * 1000000000LL;
constexpr std::int64_t kMs = 1000000;

/// The planned messages in write order: /lidar on two connections, /imu, and /never (no
/// messages). Sizes include 0 and 10000 bytes (chunks hold 2048); some times jump back 120 ms
/// into earlier chunks, some repeat the previous time.
struct Plan {
  std::vector<std::uint32_t> connection;  ///< per message: 0, 1 (/lidar) or 2 (/imu)
  std::vector<Message> messages;
};

inline Plan make_plan() {
  Plan plan;
  const char* topics[] = {"/lidar", "/lidar", "/imu"};
  std::int64_t t = kBase;
  for (int i = 0; i < 150; ++i) {
    const auto conn = static_cast<std::uint32_t>(i % 3);
    std::size_t size = static_cast<std::size_t>(i * 37 % 700);
    if (i % 17 == 0) size = 0;
    if (i % 29 == 5) size = 10000;
    if (i % 11 != 3) t = kBase + i * 10 * kMs;  // else: the previous message's time
    const std::int64_t time = i % 9 == 4 ? t - 120 * kMs : t;
    Bytes data(size);
    for (std::size_t k = 0; k < size; ++k) data[k] = static_cast<unsigned char>(i * 31 + k * 7);
    plan.connection.push_back(conn);
    plan.messages.push_back({topics[conn], time, data});
  }
  return plan;
}

inline void write_plan(const fs::path& file, const Plan& plan, Codec codec, bool index) {
  Ros1BagWriter w(file, {codec, 2048, index});
  w.add_connection(string_connection("/lidar", "/driver_a"));
  w.add_connection(string_connection("/lidar", "/driver_b"));
  auto imu = string_connection("/imu");
  imu.type = "sensor_msgs/Imu";
  w.add_connection(imu);
  w.add_connection(string_connection("/never"));
  for (std::size_t k = 0; k < plan.messages.size(); ++k) {
    const Message& m = plan.messages[k];
    w.write(plan.connection[k], m.time_ns, m.data.data(), m.data.size());
  }
  w.close();
}

/// Messages in time order, ties in write (= file) order.
inline std::vector<Message> time_ordered(std::vector<Message> m) {
  std::stable_sort(m.begin(), m.end(),
                   [](const Message& a, const Message& b) { return a.time_ns < b.time_ns; });
  return m;
}

template <typename Keep>
std::vector<Message> only(const std::vector<Message>& all, Keep keep) {
  std::vector<Message> out;
  std::copy_if(all.begin(), all.end(), std::back_inserter(out), keep);
  return out;
}

inline void check_topic(const Ros1Bag& bag, const std::vector<Message>& expected,
                        const std::string& name, const std::string& type, std::size_t connections) {
  const auto mine = only(expected, [&](const Message& m) { return m.topic == name; });
  const auto& info = bag.topics()[topic_index(bag, name)];
  CHECK(info.type == type);
  CHECK(info.serialization == ulc::bags::Serialization::ros1);
  CHECK(info.connections == connections);
  CHECK(info.message_count == mine.size());
  CHECK(info.first_time_ns == mine.front().time_ns);
  CHECK(info.last_time_ns == mine.back().time_ns);
}

/// Where a message view points: for an uncompressed chunk its message data record, else its
/// chunk record.
inline void check_offsets(const Ros1Bag& bag, const fs::path& file, Codec codec) {
  const Bytes bytes = file_bytes(file);
  bag.read(all_topics(bag), {}, [&](const ulc::bags::MessageView& m) {
    REQUIRE(m.file != nullptr);
    REQUIRE(*m.file == file.string());
    REQUIRE(m.offset + 8 < bytes.size());
    const auto header = ulc::io::load_le<std::uint32_t>(bytes.data() + m.offset);
    const ulc::bags::ros1::Place place{m.file, m.offset, Codec::none};
    const ulc::bags::ros1::FieldList f(bytes.data() + m.offset + 4, header, place, 4);
    if (codec == Codec::none) {
      CHECK(f.op() == 0x02);
      const std::uint64_t data_at = m.offset + 8 + header;
      REQUIRE(data_at + m.size <= bytes.size());
      CHECK(std::equal(m.data, m.data + m.size, bytes.data() + data_at));
    } else {
      CHECK(f.op() == 0x05);
    }
    return true;
  });
}

inline void check_round_trip(Codec codec, bool index) {
  TempDir dir;
  const auto file = dir / "plan.bag";
  const Plan plan = make_plan();
  write_plan(file, plan, codec, index);
  const auto expected = time_ordered(plan.messages);

  const Ros1Bag bag(file);
  CHECK(bag.indexed() == index);
  if (index) {
    CHECK(bag.warnings().empty());
    REQUIRE(bag.topics().size() == 3);
    CHECK(bag.topics()[2].name == "/never");
    CHECK(bag.topics()[2].message_count == 0);
    CHECK(bag.topics()[2].first_time_ns == 0);
  } else {
    // Without an index a connection is known from its first message's chunk only.
    REQUIRE(bag.warnings().size() == 1);
    CHECK(bag.warnings()[0].find("linear scan") != std::string::npos);
    REQUIRE(bag.topics().size() == 2);
  }
  CHECK(bag.topics()[0].name == "/imu");
  CHECK(bag.topics()[1].name == "/lidar");
  check_topic(bag, expected, "/lidar", "std_msgs/String", 2);
  check_topic(bag, expected, "/imu", "sensor_msgs/Imu", 1);

  CHECK(read_all(bag) == expected);

  const std::size_t imu = topic_index(bag, "/imu");
  CHECK(read_messages(bag, {imu}) ==
        only(expected, [](const Message& m) { return m.topic == "/imu"; }));
  CHECK(read_messages(bag, {}).empty());

  const TimeWindow window{kBase + 300 * kMs, kBase + 905 * kMs};
  const auto inside = only(expected, [&](const Message& m) { return window.contains(m.time_ns); });
  REQUIRE(inside.size() > 10);
  CHECK(read_messages(bag, all_topics(bag), window) == inside);
  const std::size_t lidar = topic_index(bag, "/lidar");
  CHECK(read_messages(bag, {lidar}, window) ==
        only(inside, [](const Message& m) { return m.topic == "/lidar"; }));

  check_offsets(bag, file, codec);
}

TEST_CASE("ros1 bag: round trip, uncompressed, indexed") {
  check_round_trip(Codec::none, true);
}
TEST_CASE("ros1 bag: round trip, bz2, indexed") {
  check_round_trip(Codec::bz2, true);
}
TEST_CASE("ros1 bag: round trip, lz4, indexed") {
  check_round_trip(Codec::lz4, true);
}
TEST_CASE("ros1 bag: round trip without index (linear scan), uncompressed") {
  check_round_trip(Codec::none, false);
}
TEST_CASE("ros1 bag: round trip without index (linear scan), bz2") {
  check_round_trip(Codec::bz2, false);
}
TEST_CASE("ros1 bag: round trip without index (linear scan), lz4") {
  check_round_trip(Codec::lz4, false);
}

TEST_CASE("ros1 bag: more chunks overlapping in time than the cursor keeps open") {
  // 30 chunks of 10 messages, each chunk spanning the whole time range.
  for (const Codec codec : {Codec::none, Codec::lz4}) {
    TempDir dir;
    const auto file = dir / "overlap.bag";
    std::vector<Message> written;
    {
      Ros1BagWriter w(file, {codec, 200, true});
      const auto c = w.add_connection(string_connection("/x"));
      for (int i = 0; i < 300; ++i) {
        const std::int64_t t = kBase + (i % 10) * 1000 + i / 10;
        const Bytes data(static_cast<std::size_t>(i % 7 + 1), static_cast<unsigned char>(i));
        w.write(c, t, data.data(), data.size());
        written.push_back({"/x", t, data});
      }
    }
    const Ros1Bag bag(file);
    CHECK(read_all(bag) == time_ordered(written));
  }
}

TEST_CASE("ros1 bag: two cursors open at once read the same messages") {
  TempDir dir;
  const auto file = dir / "two.bag";
  const Plan plan = make_plan();
  write_plan(file, plan, Codec::lz4, true);
  const Ros1Bag bag(file);
  const auto a = bag.cursor(all_topics(bag), {});
  const auto b = bag.cursor(all_topics(bag), {});
  ulc::bags::MessageView ma, mb;
  std::size_t n = 0;
  while (a->next(ma)) {
    REQUIRE(b->next(mb));
    CHECK(ma.time_ns == mb.time_ns);
    CHECK(Bytes(ma.data, ma.data + ma.size) == Bytes(mb.data, mb.data + mb.size));
    ++n;
  }
  CHECK_FALSE(b->next(mb));
  CHECK(n == plan.messages.size());
  CHECK_THROWS_AS(bag.cursor({3}, {}), std::out_of_range);
}

TEST_CASE("ros1 bag writer: the layout rosbag writes") {
  TempDir dir;
  const auto file = dir / "layout.bag";
  const Plan plan = make_plan();
  write_plan(file, plan, Codec::none, true);
  const Bytes b = file_bytes(file);
  REQUIRE(b.size() > 4117);
  CHECK(std::string(b.begin(), b.begin() + 13) == "#ROSBAG V2.0\n");
  const auto header_len = ulc::io::load_le<std::uint32_t>(b.data() + 13);
  const auto data_len = ulc::io::load_le<std::uint32_t>(b.data() + 17 + header_len);
  CHECK(header_len + data_len == 4096u);  // the bag header record padded to 4096 bytes
  const std::string name = file.string();
  const ulc::bags::ros1::Place place{&name, 0, Codec::none};
  const ulc::bags::ros1::FieldList bag_header(b.data() + 17, header_len, place, 17);
  const auto index_pos = bag_header.u64("index_pos");
  CHECK(bag_header.u32("conn_count") == 4u);
  CHECK(index_pos > 4117u);
  CHECK(index_pos < b.size());
  const auto chunk_len = ulc::io::load_le<std::uint32_t>(b.data() + 4117);
  const ulc::bags::ros1::FieldList chunk(b.data() + 4121, chunk_len, place, 4121);
  CHECK(chunk.op() == 0x05);
  CHECK(chunk.text("compression") == "none");
}

TEST_CASE("ros1 bag writer: errors are IoErrors") {
  TempDir dir;
  CHECK_THROWS_AS(Ros1BagWriter(dir / "no_such_folder" / "x.bag"), ulc::io::IoError);
  Ros1BagWriter w(dir / "w.bag");
  const auto c = w.add_connection(string_connection("/a"));
  const unsigned char byte = 1;
  CHECK_THROWS_AS(w.write(c + 1, 0, &byte, 1), ulc::io::IoError);
  CHECK_THROWS_AS(w.write(c, -1, &byte, 1), ulc::io::IoError);
  CHECK_THROWS_AS(w.write(c, std::int64_t{1} << 62, &byte, 1), ulc::io::IoError);
  w.write(c, 5, &byte, 1);
  w.close();
  CHECK_THROWS_AS(w.write(c, 6, &byte, 1), ulc::io::IoError);
  const Ros1Bag bag(dir / "w.bag");
  REQUIRE(bag.topics().size() == 1);
  CHECK(bag.topics()[0].message_count == 1);
  CHECK(bag.topics()[0].first_time_ns == 5);
}

}  // namespace ros1_roundtrip
