// Damaged MCAP files: cut at every byte, bytes flipped, absurd lengths. Opening and reading all
// messages either succeeds or throws one io::IoError naming the file and a byte; anything else
// (another exception, a crash, a huge allocation) fails the test.
#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "../support/temp_dir.hpp"
#include "test_paths.hpp"
#include "ulc/bags/mcap_reader.hpp"
#include "ulc/bags/mcap_writer.hpp"

namespace mcap_robust_test {

namespace fs = std::filesystem;
using ulc::bags::Codec;
using ulc::bags::McapReader;
using ulc::bags::McapWriteOptions;
using ulc::bags::McapWriter;
using ulc::bags::MessageView;

/// A fresh folder under the system temp dir (tests/support/temp_dir.hpp).
struct Scratch : ulc_test::TempDir {
  Scratch() : ulc_test::TempDir("ulc_test_mcap_robust") {}
};
/// Message i of the sample: 4 bytes of i, then (i % 23) * 3 bytes derived from i.
std::vector<unsigned char> payload(std::uint32_t i) {
  std::vector<unsigned char> d(4 + (i % 23) * 3);
  for (int k = 0; k < 4; ++k)
    d[static_cast<std::size_t>(k)] = static_cast<unsigned char>(i >> (8 * k));
  for (std::size_t k = 4; k < d.size(); ++k) d[k] = static_cast<unsigned char>(i * 11 + k);
  return d;
}

std::int64_t time_of(std::uint32_t i) {
  return 5000 + (i * 7) % 40;
}

void write_small(const fs::path& file, const McapWriteOptions& o) {
  McapWriter w(file, o);
  const auto s = w.add_schema("std_msgs/msg/String", "ros2msg", "string data");
  const std::uint16_t ch[] = {w.add_channel("/x", s, "cdr"), w.add_channel("/y", s, "cdr")};
  for (std::uint32_t i = 0; i < 40; ++i) {
    const auto d = payload(i);
    w.write(ch[i % 2], time_of(i), time_of(i), d.data(), d.size());
  }
}

struct Outcome {
  bool ok = false;
  std::size_t messages = 0;
};

/// Opens and reads everything. Messages read must be messages written (a prefix of the file
/// holds some of them, whole). Only io::IoError may escape, naming the file and a byte.
Outcome open_and_read(const fs::path& file, bool check_payloads) {
  Outcome out;
  try {
    McapReader r(file);
    std::vector<std::size_t> all;
    for (std::size_t k = 0; k < r.topics().size(); ++k) all.push_back(k);
    r.read(all, {}, [&](const MessageView& m) {
      ++out.messages;
      if (check_payloads) {
        REQUIRE(m.size >= 4);
        const std::uint32_t i = m.data[0] | (m.data[1] << 8) | (m.data[2] << 16) |
                                (static_cast<std::uint32_t>(m.data[3]) << 24);
        REQUIRE(i < 40);
        REQUIRE(std::vector<unsigned char>(m.data, m.data + m.size) == payload(i));
        REQUIRE(m.time_ns == time_of(i));
      }
      return true;
    });
    out.ok = true;
  } catch (const ulc::io::IoError& e) {
    if (e.file() != file.string() || e.position().rfind("byte ", 0) != 0)
      FAIL("IoError without file and byte: " << e.what());
  } catch (const std::exception& e) {
    FAIL("not an IoError: " << e.what());
  } catch (...) {
    FAIL("not an IoError");
  }
  return out;
}

std::vector<unsigned char> bytes_of(const fs::path& file) {
  std::ifstream f(file, std::ios::binary);
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(f), {});
}

void put_bytes(const fs::path& file, const std::vector<unsigned char>& b) {
  std::ofstream f(file, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

std::uint64_t get_u64(const std::vector<unsigned char>& b, std::uint64_t at) {
  std::uint64_t v = 0;
  for (int k = 7; k >= 0; --k) v = (v << 8) | b[at + static_cast<std::uint64_t>(k)];
  return v;
}

void set_le(std::vector<unsigned char>& b, std::uint64_t at, std::uint64_t v, int n) {
  for (int k = 0; k < n; ++k)
    b[at + static_cast<std::uint64_t>(k)] = static_cast<unsigned char>(v >> (8 * k));
}

/// Changes one byte of a file in place (the reader opens the file anew each time).
class BytePatcher {
 public:
  explicit BytePatcher(const fs::path& file)
      : f_(file, std::ios::in | std::ios::out | std::ios::binary) {}
  void set(std::uint64_t at, unsigned char v) {
    f_.seekp(static_cast<std::streamoff>(at));
    f_.put(static_cast<char>(v));
    f_.flush();
  }

 private:
  std::fstream f_;
};

/// (opcode, offset) of the top-level records of a complete file, Footer included.
std::vector<std::pair<std::uint8_t, std::uint64_t>> top_records(
    const std::vector<unsigned char>& b) {
  std::vector<std::pair<std::uint8_t, std::uint64_t>> out;
  for (std::uint64_t p = 8; p + 9 <= b.size() - 8;) {
    out.emplace_back(b[p], p);
    if (b[p] == 0x02) break;
    p += 9 + get_u64(b, p + 1);
  }
  return out;
}

std::uint64_t first_of(const std::vector<unsigned char>& b, std::uint8_t op, std::size_t nth = 0) {
  for (const auto& [o, at] : top_records(b))
    if (o == op && nth-- == 0) return at;
  FAIL("no record with opcode " << int(op));
  return 0;
}

/// Zeroes the Footer's summary_crc and the first chunk's uncompressed_crc, so that a damaged
/// length reaches the length checks rather than a CRC check.
void drop_crcs(std::vector<unsigned char>& b) {
  set_le(b, b.size() - 8 - 4, 0, 4);
  for (const auto& [op, at] : top_records(b))
    if (op == 0x06) set_le(b, at + 9 + 24, 0, 4);
}

struct Variant {
  std::string name;
  McapWriteOptions options;
};

std::vector<Variant> variants() {
  std::vector<Variant> v;
  for (Codec c : {Codec::none, Codec::zstd, Codec::lz4})
    for (bool summary : {true, false}) {
      McapWriteOptions o;
      o.compression = c;
      o.write_summary = summary;
      o.chunk_bytes = 300;
      v.push_back({std::string(ulc::bags::codec_name(c)) + (summary ? "+summary" : ""), o});
    }
  for (bool summary : {true, false}) {
    McapWriteOptions o;
    o.chunked = false;
    o.write_summary = summary;
    v.push_back({std::string("unchunked") + (summary ? "+summary" : ""), o});
  }
  return v;
}

}  // namespace mcap_robust_test

using namespace mcap_robust_test;

TEST_CASE("mcap files cut at every byte: an IoError naming the file and a byte", "[mcap]") {
  Scratch dir;
  const fs::path file = dir / "cut.mcap";
  for (const Variant& v : variants()) {
    INFO(v.name);
    write_small(file, v.options);
    const auto full = open_and_read(file, true);
    REQUIRE(full.ok);
    REQUIRE(full.messages == 40);
    const std::uint64_t size = fs::file_size(file);
    std::size_t read = 0;
    for (std::uint64_t n = size; n-- > 0;) {
      fs::resize_file(file, n);
      INFO("cut at " << n << " of " << size);
      const Outcome o = open_and_read(file, true);
      if (o.ok) ++read;
      CHECK(o.messages <= 40);
    }
    CHECK(read == 0);  // a file without its end is damaged: never read as if whole
  }
}

TEST_CASE("mcap files with flipped bytes: success or an IoError", "[mcap]") {
  Scratch dir;
  const fs::path file = dir / "flip.mcap";
  for (const Variant& v : variants()) {
    INFO(v.name);
    write_small(file, v.options);
    const auto clean = bytes_of(file);
    BytePatcher patch(file);
    for (std::uint64_t at = 0; at < clean.size(); ++at) {
      patch.set(at, static_cast<unsigned char>(clean[at] ^ (at % 2 ? 0xFF : 0x10)));
      INFO("byte " << at << " flipped");
      open_and_read(file, false);
      patch.set(at, clean[at]);
    }
  }
}

TEST_CASE("mcap absurd lengths: an IoError, no allocation", "[mcap]") {
  Scratch dir;
  const fs::path file = dir / "lengths.mcap";
  for (const Variant& v : variants()) {
    INFO(v.name);
    write_small(file, v.options);
    auto clean = bytes_of(file);
    drop_crcs(clean);
    const std::uint64_t huge = std::uint64_t{1} << 40;
    std::vector<std::pair<std::string, std::vector<unsigned char>>> cases;
    // The length of the first record after the Header (a Chunk, or a Schema when unchunked).
    auto b = clean;
    const std::uint64_t header = first_of(b, 0x01);
    set_le(b, header + 9 + get_u64(b, header + 1) + 1, huge, 8);
    cases.emplace_back("data record length 2^40", b);
    // The Header's profile string.
    b = clean;
    set_le(b, first_of(b, 0x01) + 9, 0xFFFFFFFFu, 4);
    cases.emplace_back("Header profile length 2^32-1", b);
    if (v.options.write_summary) {
      // The first summary Channel record's topic; the first ChunkIndex's record length.
      const auto recs = top_records(clean);
      std::uint64_t summary_channel = 0;
      for (const auto& [op, at] : recs)
        if (op == 0x04) summary_channel = at;  // the last Channel: in the summary
      b = clean;
      set_le(b, summary_channel + 9 + 4, 0xFFFFFFFFu, 4);
      cases.emplace_back("summary Channel topic length 2^32-1", b);
      b = clean;
      set_le(b, first_of(b, 0x0B) + 1, huge, 8);
      cases.emplace_back("Statistics record length 2^40", b);
      if (v.options.chunked) {
        b = clean;
        const std::uint64_t ci = first_of(b, 0x08);
        set_le(b, ci + 9 + 16 + 8, huge, 8);  // chunk_length
        cases.emplace_back("ChunkIndex chunk_length 2^40", b);
        b = clean;
        set_le(b, first_of(b, 0x07) + 1, huge, 8);
        cases.emplace_back("MessageIndex record length 2^40", b);
      }
    }
    if (v.options.chunked && v.options.compression == Codec::none && !v.options.write_summary) {
      // (With a summary, an indexed chunk's Schema and Channel records are never parsed: the
      // summary's copies are used, the messages are found through the message indexes.)
      // A Channel record inside the first chunk: Schema first, then the Channel's topic.
      b = clean;
      const std::uint64_t records = first_of(b, 0x06) + 9 + 8 + 8 + 8 + 4 + 4 + 8;
      const std::uint64_t channel = records + 9 + get_u64(b, records + 1);
      REQUIRE(b[channel] == 0x04);
      set_le(b, channel + 9 + 4, 0xFFFFFFFFu, 4);
      cases.emplace_back("in-chunk Channel topic length 2^32-1", b);
      b = clean;
      set_le(b, records + 1, huge, 8);
      cases.emplace_back("in-chunk Schema record length 2^40", b);
    }
    for (const auto& [what, bytes] : cases) {
      INFO(what);
      put_bytes(file, bytes);
      const Outcome o = open_and_read(file, false);
      CHECK(!o.ok);
    }
  }
}

TEST_CASE("mcap real files cut at every byte and flipped", "[mcap][shared]") {
  const fs::path bags = ulc_test::bags_dir();
  ULC_SKIP_UNLESS(!bags.empty(), "../shared/data/bags is absent");
  Scratch dir;
  const fs::path file = dir / "real.mcap";
  for (const char* name : {"talker/talker.mcap", "cdr_test/cdr_test_0.mcap"}) {
    INFO(name);
    const auto clean = bytes_of(bags / "ros2" / "mcap" / name);
    put_bytes(file, clean);
    REQUIRE(open_and_read(file, false).ok);
    {
      BytePatcher patch(file);
      for (std::uint64_t at = 0; at < clean.size(); at += 3) {
        patch.set(at, static_cast<unsigned char>(clean[at] ^ 0x81));
        open_and_read(file, false);
        patch.set(at, clean[at]);
      }
    }
    for (std::uint64_t n = clean.size(); n-- > 0;) {
      fs::resize_file(file, n);
      open_and_read(file, false);
    }
  }
}
