#include <catch2/catch.hpp>
#include <random>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "ulc/io/lzf.hpp"

using io_test::Bytes;
using ulc::io::lzf_compress;
using ulc::io::lzf_decompress;
using ulc::io::LzfStatus;

namespace {

Bytes decode(const Bytes& in, std::size_t capacity, ulc::io::LzfResult* result = nullptr) {
  Bytes out(capacity);
  const auto r = lzf_decompress(in.data(), in.size(), out.data(), out.size());
  if (result) *result = r;
  REQUIRE(r.output_size <= capacity);
  out.resize(r.output_size);
  return out;
}

Bytes round_trip(const Bytes& data) {
  const Bytes packed = lzf_compress(data);
  ulc::io::LzfResult r;
  const Bytes back = decode(packed, data.size(), &r);
  REQUIRE(r.ok());
  CHECK(r.input_offset == packed.size());
  return back;
}

}  // namespace

TEST_CASE("LZF decoder: literal, back-reference, overlapping and extended references", "[lzf]") {
  Bytes stream = {2,    'a',  'b', 'c',  // literal "abc"
                  0x80, 0x02,            // length 4+2 = 6 from 3 back: overlaps its own output
                  0,    'X',             // literal "X"
                  0,    'Y',             // literal "Y"
                  0xE0, 11,   0x00};     // length 7+11+2 = 20 from 1 back: a run of 'Y'
  const std::string expected = "abcabcabc" + std::string("X") + std::string(21, 'Y');
  ulc::io::LzfResult r;
  const Bytes out = decode(stream, expected.size(), &r);
  REQUIRE(r.ok());
  CHECK(std::string(out.begin(), out.end()) == expected);
}

TEST_CASE("LZF decoder: a distance above 256 uses the high bits of the control byte", "[lzf]") {
  Bytes data(300);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<unsigned char>(i * 7 + 1);
  Bytes stream = io_test::lzf_literals_only(data);
  // length 3+2 = 5, distance 300: (300-1) = 0x12B -> control (3 << 5) | 0x01, low byte 0x2B.
  stream.push_back(0x61);
  stream.push_back(0x2B);
  const Bytes out = decode(stream, 305);
  REQUIRE(out.size() == 305);
  CHECK(Bytes(out.begin(), out.begin() + 300) == data);
  CHECK(Bytes(out.begin() + 300, out.end()) == Bytes(data.begin(), data.begin() + 5));
}

TEST_CASE("LZF decoder rejects every malformed stream", "[lzf]") {
  struct Case {
    const char* name;
    Bytes stream;
    std::size_t capacity;
    LzfStatus status;
    std::size_t failing_chunk;
  };
  const std::vector<Case> cases = {
      {"reference with empty output", {0x20, 0x00}, 16, LzfStatus::bad_reference, 0},
      {"reference before the start", {1, 'a', 'b', 0x20, 0x02}, 16, LzfStatus::bad_reference, 3},
      {"literal past the input", {5, 'a', 'b'}, 16, LzfStatus::input_overrun, 0},
      {"missing distance byte", {0, 'a', 0x20}, 16, LzfStatus::input_overrun, 2},
      {"missing length byte", {0, 'a', 0xE0}, 16, LzfStatus::input_overrun, 2},
      {"missing distance after length", {0, 'a', 0xE0, 3}, 16, LzfStatus::input_overrun, 2},
      {"literal beyond the capacity", {3, 'a', 'b', 'c', 'd'}, 3, LzfStatus::output_overflow, 0},
      {"reference beyond the capacity", {0, 'a', 0x40, 0x00}, 3, LzfStatus::output_overflow, 2},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    ulc::io::LzfResult r;
    decode(c.stream, c.capacity, &r);
    CHECK(r.status == c.status);
    CHECK(r.input_offset == c.failing_chunk);
    CHECK(std::string(r.message()) != "ok");
  }
}

TEST_CASE("LZF encoder output decodes to the input: edge sizes and random data", "[lzf]") {
  std::mt19937 rng(7);
  for (std::size_t n : {0u, 1u, 2u, 3u, 4u, 31u, 32u, 33u, 64u, 1000u, 70000u}) {
    Bytes data(n);
    for (auto& b : data) b = static_cast<unsigned char>(rng());
    const Bytes packed = lzf_compress(data);
    INFO("n = " << n);
    CHECK(packed.size() <= n + n / 32 + 1);  // literals only cost one byte per 32
    CHECK(round_trip(data) == data);
  }
}

TEST_CASE("LZF encoder compresses repetitive data and still decodes it exactly", "[lzf]") {
  Bytes zeros(100000, 0);
  const Bytes packed = lzf_compress(zeros);
  CHECK(packed.size() < zeros.size() / 50);  // long runs become 264-byte references
  CHECK(round_trip(zeros) == zeros);

  Bytes pattern;
  for (int i = 0; i < 20000; ++i) pattern.push_back(static_cast<unsigned char>("abcd"[i % 4]));
  CHECK(lzf_compress(pattern).size() < pattern.size() / 20);
  CHECK(round_trip(pattern) == pattern);

  // Repeats farther apart than the 8 KiB window, mixed with near ones and noise.
  std::mt19937 rng(11);
  Bytes block(9000);
  for (auto& b : block) b = static_cast<unsigned char>(rng() % 4);
  Bytes mixed;
  for (int copy = 0; copy < 2; ++copy)
    for (unsigned char b : block) mixed.push_back(b);
  for (int i = 0; i < 5000; ++i) mixed.push_back(static_cast<unsigned char>(i % 251));
  CHECK(round_trip(mixed) == mixed);

  // Float columns like a PCD field: smooth values compress, decode bit-exact.
  Bytes floats;
  for (int i = 0; i < 10000; ++i) {
    const float v = static_cast<float>(i / 100);
    const auto* p = reinterpret_cast<const unsigned char*>(&v);
    floats.insert(floats.end(), p, p + 4);
  }
  CHECK(round_trip(floats) == floats);
}

TEST_CASE("LZF round trip holds for many random repetitive buffers", "[lzf]") {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = rng() % 5000;
    const unsigned alphabet = 1 + rng() % 8;
    Bytes data(n);
    for (auto& b : data) b = static_cast<unsigned char>(rng() % alphabet);
    INFO("trial " << trial << " n " << n);
    REQUIRE(round_trip(data) == data);
  }
}
