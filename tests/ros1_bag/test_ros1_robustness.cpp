// Ros1Bag on damaged files: cut at every byte, bytes flipped, length fields set to absurd values.
// Each must open and read (a part of) the messages or throw one io::IoError naming the file and
// a byte; anything else fails. A global allocation probe checks that no absurd length is
// allocated before it is checked.
#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <new>

#include "ros1_test_util.hpp"
#include "ulc/io/endian.hpp"

namespace ros1_alloc_probe {
std::atomic<bool> active{false};
std::atomic<std::size_t> largest{0};

/// Records the largest single allocation while alive.
class Probe {
 public:
  Probe() {
    largest = 0;
    active = true;
  }
  ~Probe() { active = false; }
  std::size_t largest_allocation() const { return largest; }
};
}  // namespace ros1_alloc_probe

__attribute__((noinline)) void* operator new(std::size_t n) {
  if (ros1_alloc_probe::active.load(std::memory_order_relaxed)) {
    std::size_t seen = ros1_alloc_probe::largest.load(std::memory_order_relaxed);
    while (n > seen && !ros1_alloc_probe::largest.compare_exchange_weak(seen, n)) {
    }
  }
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
__attribute__((noinline)) void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return operator new(n);
  } catch (...) {
    return nullptr;
  }
}
// Out of line, so that the compiler does not pair a visible free() with a new-expression.
__attribute__((noinline)) void operator delete(void* p) noexcept {
  std::free(p);
}
__attribute__((noinline)) void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
__attribute__((noinline)) void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

namespace ros1_robustness {

using namespace ros1_test;
using ulc::bags::Ros1Bag;

constexpr std::size_t kBagHeaderEnd = 13 + 4096 + 8;
/// Far more than any buffer the small test bags need.
constexpr std::size_t kAllocationLimit = std::size_t{16} << 20;

enum class Outcome { read, io_error, other };

/// Opens `file` and reads all its messages into `out`. An IoError must name the file and a byte.
inline Outcome open_and_read(const fs::path& file, std::vector<Message>& out, std::string& why) {
  try {
    const Ros1Bag bag(file);
    out = read_all(bag);
    return Outcome::read;
  } catch (const ulc::io::IoError& e) {
    why = e.what();
    const bool named =
        why.find(file.string()) != std::string::npos && why.find("byte ") != std::string::npos;
    return named ? Outcome::io_error : Outcome::other;
  } catch (const std::exception& e) {
    why = std::string("not an IoError: ") + e.what();
  } catch (...) {
    why = "an exception that is not a std::exception";
  }
  return Outcome::other;
}

/// Checks one damaged file; returns its outcome.
inline Outcome check_damaged(const fs::path& file, const std::string& damage) {
  std::vector<Message> read;
  std::string why;
  ros1_alloc_probe::Probe probe;
  const Outcome outcome = open_and_read(file, read, why);
  if (outcome == Outcome::other) FAIL_CHECK(damage << ": " << why);
  if (probe.largest_allocation() > kAllocationLimit)
    FAIL_CHECK(damage << ": allocated " << probe.largest_allocation() << " bytes at once");
  return outcome;
}

inline std::uint64_t index_pos_of(const Bytes& b) {
  const std::string name = "bag";
  const ulc::bags::ros1::Place place{&name, 0, Codec::none};
  const auto header_len = ulc::io::load_le<std::uint32_t>(b.data() + 13);
  return ulc::bags::ros1::FieldList(b.data() + 17, header_len, place, 17).u64("index_pos");
}

/// Every message read from a cut file is one that was written.
inline bool all_written(const std::vector<Message>& read, std::vector<Message> written) {
  std::sort(written.begin(), written.end());
  return std::all_of(read.begin(), read.end(), [&](const Message& m) {
    return std::binary_search(written.begin(), written.end(), m);
  });
}

inline void check_cuts(Codec codec, bool index) {
  TempDir dir;
  const auto full = dir / "full.bag";
  const auto written = write_small_bag(full, codec, index);
  const Bytes bytes = file_bytes(full);
  const std::uint64_t index_pos = index ? index_pos_of(bytes) : bytes.size();
  const auto cut = dir / "cut.bag";
  fs::copy_file(full, cut);
  for (std::size_t n = bytes.size() + 1; n-- > 0;) {
    fs::resize_file(cut, n);
    std::vector<Message> read;
    std::string why;
    ros1_alloc_probe::Probe probe;
    const Outcome outcome = open_and_read(cut, read, why);
    if (outcome == Outcome::other) FAIL_CHECK("cut at " << n << ": " << why);
    // An unfinished recording (no index) reads its complete chunks by a linear scan; a closed
    // bag cut before the end of its index is damaged: an error.
    if (!index && n >= kBagHeaderEnd && outcome != Outcome::read)
      FAIL_CHECK("cut at " << n << " of an unfinished recording: " << why);
    if (index && n < bytes.size() && n <= index_pos && outcome == Outcome::read)
      FAIL_CHECK("cut at " << n << " before the index was read without an error");
    if (outcome == Outcome::read && !all_written(read, written))
      FAIL_CHECK("cut at " << n << ": a message that was not written");
    if (n == bytes.size() && read.size() != written.size()) FAIL_CHECK("the whole file");
    if (probe.largest_allocation() > kAllocationLimit) FAIL_CHECK("cut at " << n << ": memory");
  }
}

TEST_CASE("ros1 bag: cut at every byte, indexed") {
  for (const Codec c : {Codec::none, Codec::bz2, Codec::lz4}) check_cuts(c, true);
}
TEST_CASE("ros1 bag: cut at every byte, unindexed") {
  for (const Codec c : {Codec::none, Codec::bz2, Codec::lz4}) check_cuts(c, false);
}

/// Writes `value` (`width` bytes, little endian) at `at` of a copy of `bytes`.
inline void write_patched(const fs::path& file, Bytes bytes, std::size_t at, std::uint64_t value,
                          int width) {
  for (int k = 0; k < width; ++k)
    bytes[at + static_cast<std::size_t>(k)] = static_cast<unsigned char>(value >> (8 * k));
  write_bytes(file, bytes);
}

inline void check_flips(Codec codec, bool index) {
  TempDir dir;
  const auto full = dir / "full.bag";
  write_small_bag(full, codec, index);
  Bytes bytes = file_bytes(full);
  const auto damaged = dir / "damaged.bag";
  write_bytes(damaged, bytes);
  std::fstream io(damaged, std::ios::in | std::ios::out | std::ios::binary);
  std::size_t errors = 0;
  for (std::size_t at = 0; at < bytes.size(); ++at) {
    for (const unsigned char mask : {0xff, 0x01, 0x80}) {
      io.seekp(static_cast<std::streamoff>(at));
      io.put(static_cast<char>(bytes[at] ^ mask));
      io.flush();
      const std::string damage = "byte " + std::to_string(at) + " ^ " + std::to_string(mask);
      errors += check_damaged(damaged, damage) == Outcome::io_error;
      io.seekp(static_cast<std::streamoff>(at));
      io.put(static_cast<char>(bytes[at]));
      io.flush();
    }
  }
  CHECK(errors > 100);  // the damage was seen
}

TEST_CASE("ros1 bag: every byte flipped") {
  for (const Codec c : {Codec::none, Codec::bz2, Codec::lz4}) {
    check_flips(c, true);
    check_flips(c, false);
  }
}

/// A length or position field of a written bag, and whether setting it to an absurd value must
/// make an IoError (`strict`) or may still read (a connection record inside a chunk is not read
/// when the index is).
struct Field {
  std::size_t at;
  int width;
  bool strict;
  std::string what;
};

inline std::uint8_t op_of(const Bytes& b, std::size_t header, std::size_t size) {
  for (std::size_t p = header; p + 4 <= header + size;) {
    const auto len = ulc::io::load_le<std::uint32_t>(b.data() + p);
    if (len == 4 && std::equal(b.begin() + p + 4, b.begin() + p + 7, "op=")) return b[p + 7];
    p += 4 + len;
  }
  return 0;
}

/// The fields of the records from `pos` to `end`, and of the records in uncompressed chunks.
inline void list_fields(const Bytes& b, std::size_t pos, std::size_t end, bool in_chunk,
                        bool indexed, std::vector<Field>& out) {
  while (pos + 8 <= end) {
    const auto header_len = ulc::io::load_le<std::uint32_t>(b.data() + pos);
    const std::size_t header = pos + 4;
    const std::uint8_t op = op_of(b, header, header_len);
    const bool strict = !in_chunk || op == 0x02;
    const std::string where =
        " of the op " + std::to_string(op) + " record at " + std::to_string(pos);
    out.push_back({pos, 4, strict, "header length" + where});
    bool uncompressed = false;
    for (std::size_t p = header; p < header + header_len;) {
      const auto len = ulc::io::load_le<std::uint32_t>(b.data() + p);
      const std::string text(b.begin() + p + 4, b.begin() + p + 4 + len);
      const std::string name = text.substr(0, text.find('='));
      const std::size_t value = p + 4 + name.size() + 1;
      out.push_back({p, 4, strict, "length of field " + name + where});
      if (op == 0x05 && name == "size") out.push_back({value, 4, true, "chunk size" + where});
      if (op == 0x05 && name == "compression") uncompressed = text == "compression=none";
      if (op == 0x03 && name == "index_pos") out.push_back({value, 8, false, "index_pos"});
      if (op == 0x06 && name == "chunk_pos") out.push_back({value, 8, indexed, "chunk_pos"});
      if ((op == 0x06 || op == 0x04) && name == "count")
        out.push_back({value, 4, indexed, "count" + where});
      p += 4 + len;
    }
    const std::size_t data_len_at = header + header_len;
    const auto data_len = ulc::io::load_le<std::uint32_t>(b.data() + data_len_at);
    out.push_back({data_len_at, 4, strict, "data length" + where});
    if (op == 0x05 && uncompressed)
      list_fields(b, data_len_at + 4, data_len_at + 4 + data_len, true, indexed, out);
    pos = data_len_at + 4 + data_len;
  }
}

inline void check_absurd_lengths(Codec codec, bool index) {
  TempDir dir;
  const auto full = dir / "full.bag";
  write_small_bag(full, codec, index);
  const Bytes bytes = file_bytes(full);
  std::vector<Field> fields;
  list_fields(bytes, 13, bytes.size(), false, index, fields);
  REQUIRE(fields.size() > 30);
  const auto damaged = dir / "damaged.bag";
  for (const Field& f : fields) {
    const std::vector<std::uint64_t> values =
        f.width == 4 ? std::vector<std::uint64_t>{0xffffffffu, 0x80000000u, 0x40000001u}
                     : std::vector<std::uint64_t>{std::uint64_t{1} << 40, ~std::uint64_t{0}};
    for (const std::uint64_t v : values) {
      write_patched(damaged, bytes, f.at, v, f.width);
      const std::string damage = f.what + " = " + std::to_string(v);
      const Outcome outcome = check_damaged(damaged, damage);
      if (f.strict && outcome != Outcome::io_error) FAIL_CHECK(damage << ": no IoError");
    }
  }
}

TEST_CASE("ros1 bag: length fields of 2^32-1, 2^31, 2^30+1 and 2^40") {
  for (const Codec c : {Codec::none, Codec::bz2, Codec::lz4}) {
    check_absurd_lengths(c, true);
    check_absurd_lengths(c, false);
  }
}

TEST_CASE("ros1 bag: an index_pos past the end of the file is a truncated bag") {
  TempDir dir;
  const auto full = dir / "full.bag";
  const auto written = write_small_bag(full, Codec::lz4, true);
  Bytes bytes = file_bytes(full);
  std::vector<Field> fields;
  list_fields(bytes, 13, bytes.size(), false, true, fields);
  const auto f = std::find_if(fields.begin(), fields.end(),
                              [](const Field& x) { return x.what == "index_pos"; });
  REQUIRE(f != fields.end());
  write_patched(dir / "far.bag", bytes, f->at, std::uint64_t{1} << 40, 8);
  REQUIRE_THROWS_WITH(Ros1Bag(dir / "far.bag"),
                      Catch::Contains("far.bag: byte " + std::to_string(bytes.size())) &&
                          Catch::Contains("truncated bag"));
  (void)written;
}

TEST_CASE("ros1 bag: a message of an undefined connection is an IoError") {
  TempDir dir;
  const auto full = dir / "full.bag";
  write_small_bag(full, Codec::none, false);
  const Bytes bytes = file_bytes(full);
  std::vector<Field> fields;
  list_fields(bytes, 13, bytes.size(), false, false, fields);
  // The conn field's value follows "conn=" in the first message data record.
  const auto f = std::find_if(fields.begin(), fields.end(), [](const Field& x) {
    return x.what.rfind("length of field conn of the op 2 record", 0) == 0;
  });
  REQUIRE(f != fields.end());
  write_patched(dir / "conn.bag", bytes, f->at + 9, 77, 4);
  CHECK_THROWS_WITH(Ros1Bag(dir / "conn.bag"), Catch::Contains("connection 77"));
}

}  // namespace ros1_robustness

namespace ros1_robustness {

TEST_CASE("ros1 bag: the unfinished last chunk of a recording (sizes still 0) is skipped") {
  TempDir dir;
  const auto file = dir / "active.bag";
  auto written = write_small_bag(file, Codec::none, false);
  Bytes bytes = file_bytes(file);
  // rosbag writes a chunk's header with sizes 0 first; records follow until the chunk closes.
  ulc::bags::ros1::FieldWriter chunk;
  chunk.op(ulc::bags::ros1::Op::chunk).text("compression", "none").u32("size", 0);
  const auto append_u32 = [&](std::uint32_t v) {
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<unsigned char>(v >> (8 * k)));
  };
  append_u32(static_cast<std::uint32_t>(chunk.data().size()));
  bytes.insert(bytes.end(), chunk.data().begin(), chunk.data().end());
  append_u32(0);
  ulc::bags::ros1::FieldWriter message;
  message.op(ulc::bags::ros1::Op::message_data).u32("conn", 0).time("time", 99000000000);
  append_u32(static_cast<std::uint32_t>(message.data().size()));
  bytes.insert(bytes.end(), message.data().begin(), message.data().end());
  append_u32(2);
  bytes.push_back(7);
  bytes.push_back(8);
  write_bytes(file, bytes);

  const Ros1Bag bag(file);
  REQUIRE(bag.warnings().size() == 2);
  CHECK(bag.warnings()[1].find("unfinished") != std::string::npos);
  auto read = read_all(bag);
  std::sort(read.begin(), read.end());
  std::sort(written.begin(), written.end());
  CHECK(read == written);
}

}  // namespace ros1_robustness
