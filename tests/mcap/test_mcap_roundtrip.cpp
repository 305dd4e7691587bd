// McapWriter -> McapReader round trips: every compression, with and without summary, chunked or
// not; messages of 0 bytes and bigger than a chunk, times out of order across chunks; selection
// by topic and time window; CRC mismatches detected.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "../support/temp_dir.hpp"
#include "ulc/bags/mcap_reader.hpp"
#include "ulc/bags/mcap_writer.hpp"

namespace mcap_roundtrip_test {

namespace fs = std::filesystem;
using ulc::bags::Codec;
using ulc::bags::McapReader;
using ulc::bags::McapWriteOptions;
using ulc::bags::McapWriter;
using ulc::bags::MessageView;
using ulc::bags::TimeWindow;

/// A fresh folder under the system temp dir (tests/support/temp_dir.hpp).
struct TempDir : ulc_test::TempDir {
  TempDir() : ulc_test::TempDir("ulc_test_mcap_roundtrip") {}
};
struct Written {
  std::string topic;
  std::int64_t time = 0;
  std::vector<unsigned char> data;
};

struct Read {
  std::string topic;
  std::int64_t time = 0;
  std::vector<unsigned char> data;
  bool operator==(const Read& o) const {
    return topic == o.topic && time == o.time && data == o.data;
  }
};

/// Topics /a (two channels), /b and /c (ros1); sizes 0 .. 3 * chunk_bytes; log times out of
/// order across chunks, with ties.
std::vector<Written> write_sample(const fs::path& file, const McapWriteOptions& options) {
  McapWriter w(file, options);
  const auto s_str = w.add_schema("std_msgs/msg/String", "ros2msg", "string data");
  const auto s_cloud = w.add_schema("sensor_msgs/msg/PointCloud2", "ros2msg", "# cloud");
  const auto s_ros1 = w.add_schema("std_msgs/String", "ros1msg", "string data");
  const std::uint16_t a1 = w.add_channel("/a", s_str, "cdr");
  const std::uint16_t b = w.add_channel("/b", s_cloud, "cdr");
  std::vector<Written> out;
  std::uint16_t a2 = 0, c = 0;
  for (int i = 0; i < 120; ++i) {
    if (i == 30) a2 = w.add_channel("/a", s_str, "cdr");
    if (i == 50) c = w.add_channel("/c", s_ros1, "ros1");
    const std::uint16_t ch = (i % 4 == 0 && c) ? c : (i % 3 == 0 ? b : (a2 && i % 2 ? a2 : a1));
    const std::string topic = ch == c ? "/c" : ch == b ? "/b" : "/a";
    // Times go back and forth: 1000 + ((i * 37) % 97) * 10, so later chunks hold earlier times.
    const std::int64_t t = 1'000'000 + ((i * 37) % 97) * 10;
    std::size_t size = static_cast<std::size_t>((i * 53) % 300);
    if (i % 17 == 0) size = 0;
    if (i == 7 || i == 77) size = options.chunk_bytes * 3 + 5;
    std::vector<unsigned char> data(size);
    for (std::size_t k = 0; k < size; ++k) data[k] = static_cast<unsigned char>(i * 7 + k * 13);
    w.write(ch, t, t + 1, data.data(), data.size());
    out.push_back({topic, t, data});
  }
  w.close();
  return out;
}

std::vector<Read> read_all(const McapReader& r, std::vector<std::size_t> selected = {},
                           TimeWindow window = {}) {
  if (selected.empty())
    for (std::size_t k = 0; k < r.topics().size(); ++k) selected.push_back(k);
  std::vector<Read> out;
  r.read(selected, window, [&](const MessageView& m) {
    out.push_back(
        {r.topics()[m.topic].name, m.time_ns, std::vector<unsigned char>(m.data, m.data + m.size)});
    CHECK(m.file != nullptr);
    return true;
  });
  return out;
}

/// What a reader must return: time order, ties in write (= file) order.
std::vector<Read> expected(const std::vector<Written>& w, const std::string& topic = "",
                           TimeWindow window = {}) {
  std::vector<Read> out;
  for (const auto& m : w)
    if ((topic.empty() || m.topic == topic) && window.contains(m.time))
      out.push_back({m.topic, m.time, m.data});
  std::stable_sort(out.begin(), out.end(),
                   [](const Read& a, const Read& b) { return a.time < b.time; });
  return out;
}

std::size_t topic_index(const McapReader& r, const std::string& name) {
  for (std::size_t k = 0; k < r.topics().size(); ++k)
    if (r.topics()[k].name == name) return k;
  FAIL("no topic " << name);
  return 0;
}

void flip_byte(const fs::path& file, std::uint64_t offset) {
  std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(static_cast<std::streamoff>(offset));
  char c = 0;
  f.get(c);
  f.seekp(static_cast<std::streamoff>(offset));
  f.put(static_cast<char>(c ^ 0x5A));
}

std::vector<unsigned char> file_bytes(const fs::path& file) {
  std::ifstream f(file, std::ios::binary);
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(f), {});
}

std::uint64_t u64_at(const std::vector<unsigned char>& b, std::uint64_t at) {
  std::uint64_t v = 0;
  for (int k = 7; k >= 0; --k) v = (v << 8) | b[at + static_cast<std::uint64_t>(k)];
  return v;
}

/// Offsets of the top-level records (opcode byte) of a complete file, up to the Footer.
std::vector<std::pair<std::uint8_t, std::uint64_t>> records(const std::vector<unsigned char>& b) {
  std::vector<std::pair<std::uint8_t, std::uint64_t>> out;
  for (std::uint64_t p = 8; p + 9 <= b.size() - 8;) {
    out.emplace_back(b[p], p);
    if (b[p] == 0x02) break;
    p += 9 + u64_at(b, p + 1);
  }
  return out;
}

std::string error_of(const fs::path& file) {
  try {
    McapReader r(file);
    read_all(r);
  } catch (const ulc::io::IoError& e) {
    CHECK(e.file() == file.string());
    CHECK(e.position().rfind("byte ", 0) == 0);
    return e.what();
  }
  return "";
}

}  // namespace mcap_roundtrip_test

using namespace mcap_roundtrip_test;

TEST_CASE("mcap crc32 matches the IEEE / zlib check values", "[mcap]") {
  const std::string s = "123456789";
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  CHECK(ulc::bags::mcap::crc32(p, s.size()) == 0xCBF43926u);
  CHECK(ulc::bags::mcap::crc32(p, 0) == 0u);
  // Split at every point, as the writer and reader accumulate it.
  for (std::size_t k = 0; k <= s.size(); ++k)
    CHECK(ulc::bags::mcap::crc32_update(ulc::bags::mcap::crc32(p, k), p + k, s.size() - k) ==
          0xCBF43926u);
  std::vector<unsigned char> big(1000);
  for (std::size_t k = 0; k < big.size(); ++k) big[k] = static_cast<unsigned char>(k * 31 + 7);
  std::uint32_t bytewise = 0;
  for (unsigned char c : big) bytewise = ulc::bags::mcap::crc32_update(bytewise, &c, 1);
  CHECK(ulc::bags::mcap::crc32(big.data(), big.size()) == bytewise);
}

TEST_CASE("mcap round trip: every message back in time order, counts and times", "[mcap]") {
  TempDir dir;
  for (Codec codec : {Codec::none, Codec::zstd, Codec::lz4})
    for (bool summary : {true, false})
      for (bool chunked : {true, false}) {
        if (!chunked && codec != Codec::none) continue;
        McapWriteOptions o;
        o.compression = codec;
        o.write_summary = summary;
        o.chunked = chunked;
        o.chunk_bytes = 2000;
        INFO("codec " << ulc::bags::codec_name(codec) << " summary " << summary << " chunked "
                      << chunked);
        const fs::path file = dir / "sample.mcap";
        const auto written = write_sample(file, o);
        McapReader r(file);
        CHECK(r.warnings().empty() == summary);
        REQUIRE(r.topics().size() == 3);
        const auto& a = r.topics()[0];
        CHECK(a.name == "/a");
        CHECK(a.type == "std_msgs/msg/String");
        CHECK(a.serialization == ulc::bags::Serialization::cdr);
        CHECK(a.connections == 2);
        CHECK(r.topics()[1].type == "sensor_msgs/msg/PointCloud2");
        CHECK(r.topics()[2].name == "/c");
        CHECK(r.topics()[2].serialization == ulc::bags::Serialization::ros1);
        for (const auto& t : r.topics()) {
          const auto e = expected(written, t.name);
          CHECK(t.message_count == e.size());
          CHECK(t.first_time_ns == e.front().time);
          CHECK(t.last_time_ns == e.back().time);
        }
        const auto got = read_all(r);
        const auto want = expected(written);
        REQUIRE(got.size() == want.size());
        CHECK(got == want);
      }
}

TEST_CASE("mcap round trip: selection by topic and time window", "[mcap]") {
  TempDir dir;
  for (Codec codec : {Codec::none, Codec::zstd})
    for (bool summary : {true, false}) {
      McapWriteOptions o;
      o.compression = codec;
      o.write_summary = summary;
      o.chunk_bytes = 1500;
      const fs::path file = dir / "select.mcap";
      const auto written = write_sample(file, o);
      McapReader r(file);
      CHECK(read_all(r, {topic_index(r, "/b")}) == expected(written, "/b"));
      CHECK(read_all(r, {topic_index(r, "/c")}) == expected(written, "/c"));
      const TimeWindow w{1'000'200, 1'000'500};
      CHECK(read_all(r, {}, w) == expected(written, "", w));
      CHECK(read_all(r, {topic_index(r, "/a")}, w) == expected(written, "/a", w));
      CHECK(read_all(r, {}, TimeWindow{0, 1'000'000}).empty());
      // Two cursors at once, interleaved.
      auto c1 = r.cursor({0, 1, 2}, {});
      auto c2 = r.cursor({topic_index(r, "/b")}, {});
      MessageView m1, m2;
      std::size_t n1 = 0, n2 = 0;
      const auto want_b = expected(written, "/b");
      const auto want_all = expected(written);
      while (c1->next(m1)) {
        CHECK(std::vector<unsigned char>(m1.data, m1.data + m1.size) == want_all[n1].data);
        ++n1;
        if (c2->next(m2)) {
          CHECK(std::vector<unsigned char>(m2.data, m2.data + m2.size) == want_b[n2].data);
          ++n2;
        }
      }
      CHECK(n1 == want_all.size());
      CHECK(n2 == want_b.size());
    }
}

TEST_CASE("mcap message offsets: the record for uncompressed data, the chunk otherwise", "[mcap]") {
  TempDir dir;
  for (Codec codec : {Codec::none, Codec::lz4})
    for (bool chunked : {true, false}) {
      if (!chunked && codec != Codec::none) continue;
      McapWriteOptions o;
      o.compression = codec;
      o.chunked = chunked;
      o.chunk_bytes = 1000;
      const fs::path file = dir / "offsets.mcap";
      write_sample(file, o);
      const auto bytes = file_bytes(file);
      McapReader r(file);
      r.read({0, 1, 2}, {}, [&](const MessageView& m) {
        REQUIRE(m.offset < bytes.size());
        CHECK(bytes[m.offset] == (codec == Codec::none ? 0x05 : 0x06));  // Message / Chunk
        return true;
      });
    }
}

TEST_CASE("mcap files without messages, encodings ULC does not decode", "[mcap]") {
  TempDir dir;
  const fs::path file = dir / "empty.mcap";
  {
    McapWriter w(file);
    w.add_channel("/quiet", w.add_schema("std_msgs/msg/Empty", "ros2msg", ""), "cdr");
    const auto j = w.add_channel("/json", 0, "json");
    const unsigned char msg[] = "{}";
    w.write(j, 5, 5, msg, 2);
  }
  McapReader r(file);
  REQUIRE(r.topics().size() == 2);
  CHECK(r.topics()[0].name == "/json");
  CHECK(r.topics()[0].type == "");
  CHECK(r.topics()[0].message_count == 1);
  CHECK(r.topics()[1].name == "/quiet");
  CHECK(r.topics()[1].message_count == 0);
  CHECK(read_all(r, {1}).empty());
  CHECK_THROWS_WITH(r.cursor({0}, {}),
                    Catch::Contains("message encoding 'json'") && Catch::Contains("not supported"));
}

TEST_CASE("mcap CRC mismatches are detected", "[mcap]") {
  TempDir dir;
  const fs::path file = dir / "crc.mcap";
  SECTION("a byte of an uncompressed chunk's records") {
    McapWriteOptions o;
    o.chunk_bytes = 1 << 16;
    write_sample(file, o);
    const auto recs = records(file_bytes(file));
    REQUIRE(recs[1].first == 0x06);
    flip_byte(file, recs[1].second + 500);
    CHECK_THAT(error_of(file), Catch::Contains("CRC mismatch"));
  }
  SECTION("a byte of a compressed chunk's data") {
    for (Codec codec : {Codec::zstd, Codec::lz4}) {
      McapWriteOptions o;
      o.compression = codec;
      o.chunk_bytes = 1 << 16;
      write_sample(file, o);
      const auto recs = records(file_bytes(file));
      REQUIRE(recs[1].first == 0x06);
      flip_byte(file, (recs[1].second + recs[2].second) / 2);
      const std::string e = error_of(file);
      CHECK((e.find("CRC mismatch") != std::string::npos ||
             e.find("corrupted") != std::string::npos));
    }
  }
  SECTION("a byte of a MessageIndex: the data section CRC (file read by a linear scan)") {
    McapWriteOptions o;
    o.write_summary = false;
    o.chunk_bytes = 1 << 16;
    write_sample(file, o);
    const auto recs = records(file_bytes(file));
    REQUIRE(recs[2].first == 0x07);
    flip_byte(file, recs[2].second + 20);
    CHECK_THAT(error_of(file), Catch::Contains("data section CRC mismatch"));
  }
  SECTION("a byte of the summary: the summary CRC") {
    McapWriteOptions o;
    o.chunk_bytes = 1 << 16;
    write_sample(file, o);
    const auto recs = records(file_bytes(file));
    const auto stats =
        std::find_if(recs.begin(), recs.end(), [](auto& r) { return r.first == 0x0B; });
    REQUIRE(stats != recs.end());
    flip_byte(file, stats->second + 12);
    CHECK_THAT(error_of(file), Catch::Contains("summary CRC mismatch"));
  }
}

TEST_CASE("mcap reader errors for files that are not MCAP", "[mcap]") {
  TempDir dir;
  const fs::path file = dir / "not.mcap";
  std::ofstream(file) << "hello, this is not an MCAP file at all";
  CHECK_THROWS_AS(McapReader(file), ulc::io::IoError);
  std::ofstream(file, std::ios::trunc).close();
  CHECK_THROWS_AS(McapReader(file), ulc::io::IoError);
  CHECK_THROWS_AS(McapReader(dir / "missing.mcap"), ulc::io::IoError);
}

TEST_CASE("mcap summary without usable ChunkIndex records: chunks found by the walk", "[mcap]") {
  TempDir dir;
  const fs::path file = dir / "unindexed.mcap";
  for (Codec codec : {Codec::none, Codec::zstd}) {
    McapWriteOptions o;
    o.compression = codec;
    o.chunk_bytes = 1500;
    const auto written = write_sample(file, o);
    auto bytes = file_bytes(file);
    // ChunkIndex -> an application opcode (0x80), which readers skip; summary CRC off.
    std::size_t renamed = 0;
    for (const auto& [op, at] : records(bytes))
      if (op == 0x08) {
        bytes[at] = 0x80;
        ++renamed;
      }
    REQUIRE(renamed > 3);
    for (int k = 0; k < 4; ++k) bytes[bytes.size() - 12 + static_cast<std::size_t>(k)] = 0;
    std::ofstream(file, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
    McapReader r(file);
    CHECK(r.warnings().empty());
    for (const auto& t : r.topics()) {
      const auto e = expected(written, t.name);
      CHECK(t.message_count == e.size());
      CHECK(t.first_time_ns == e.front().time);
      CHECK(t.last_time_ns == e.back().time);
    }
    CHECK(read_all(r) == expected(written));
    const TimeWindow w{1'000'300, 1'000'400};
    CHECK(read_all(r, {topic_index(r, "/b")}, w) == expected(written, "/b", w));
  }
}
