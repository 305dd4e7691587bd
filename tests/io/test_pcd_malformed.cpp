// Malformed PCD files: each gives an IoError naming the file, a position and the reason.
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "ulc/io/pcd.hpp"

using io_test::ByteBuilder;
using io_test::Bytes;
using io_test::require_io_error;

namespace {

std::size_t count_words(const std::string& s) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < s.size(); ++i) n += s[i] != ' ' && (i == 0 || s[i - 1] == ' ');
  return n;
}

std::string header(const std::string& data, std::size_t points = 2,
                   const std::string& fields = "x y z", const std::string& sizes = "4 4 4",
                   const std::string& types = "F F F") {
  std::string counts;
  for (std::size_t i = 0; i < count_words(fields); ++i) counts += " 1";
  return "# .PCD v0.7\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " + sizes + "\nTYPE " + types +
         "\nCOUNT" + counts + "\nWIDTH " + std::to_string(points) +
         "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(points) + "\nDATA " +
         data + "\n";
}

/// Writes `bytes` to a file and requires read_pcd to throw an IoError naming it with `parts`.
ulc::io::IoError expect_error(const Bytes& bytes, std::initializer_list<std::string> parts) {
  io_test::TempDir dir;
  const auto path = dir / "bad.pcd";
  io_test::write_bytes(path, bytes);
  const auto e = require_io_error([&] { ulc::io::read_pcd<ulc::PointCloud<float>>(path); }, parts);
  CHECK(e.file() == path.string());
  CHECK(std::string(e.what()).find(path.string()) == 0);
  CHECK_FALSE(e.reason().empty());
  return e;
}

ulc::io::IoError expect_error(const std::string& text, std::initializer_list<std::string> parts) {
  return expect_error(io_test::to_bytes(text), parts);
}

Bytes compressed(std::uint32_t compressed_size, std::uint32_t uncompressed_size,
                 const Bytes& payload, std::size_t points = 2) {
  ByteBuilder b;
  b.text(header("binary_compressed", points));
  b.put(compressed_size).put(uncompressed_size).raw(payload);
  return b.bytes;
}

}  // namespace

TEST_CASE("PCD: missing file and empty file", "[pcd][malformed]") {
  io_test::TempDir dir;
  require_io_error([&] { ulc::io::read_pcd<ulc::PointCloud<float>>(dir / "nope.pcd"); },
                   {"nope.pcd", "no such file"});
  expect_error(Bytes{}, {"empty file"});
}

TEST_CASE("PCD: bad header lines", "[pcd][malformed]") {
  expect_error("VERSION 0.7\nFIELDS x y z\nBOGUS 1\n", {"line 3", "unknown header line", "BOGUS"});
  expect_error(header("binary").replace(header("binary").find("FIELDS"), 6, "FIELDZ"),
               {"line 3", "unknown header line"});
  expect_error("VERSION 0.7\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
               {"line 6", "missing FIELDS"});
  expect_error("FIELDS x y z\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n", {"missing SIZE"});
  expect_error("FIELDS x y z\nSIZE 4 4 4\nWIDTH 1\nDATA ascii\n1 2 3\n", {"missing TYPE"});
  expect_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nDATA ascii\n1 2 3\n", {"missing WIDTH"});
  expect_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\n", {"missing DATA"});
  expect_error("ply\nformat ascii 1.0\n", {"line 1", "unknown header line", "'ply'"});
  expect_error("FIELDS x y z\nWIDTH 1\nWIDTH 1\n", {"line 3", "duplicate WIDTH"});
  expect_error("FIELDS x y z\nWIDTH -1\n", {"line 2", "WIDTH", "not a non-negative integer"});
  expect_error("FIELDS x y z\nWIDTH 12abc\n", {"line 2", "'12abc'"});
  expect_error(header("zip"), {"line 11", "unknown DATA kind", "'zip'"});
}

TEST_CASE("PCD: unknown TYPE/SIZE combinations and inconsistent field lists", "[pcd][malformed]") {
  expect_error(header("binary", 2, "x y z", "4 4 2", "F F F"),
               {"line 5", "field z", "TYPE F with SIZE 2"});
  expect_error(header("binary", 2, "x y z", "4 4 3", "F F U"), {"field z", "SIZE 3"});
  expect_error(header("binary", 2, "x y z", "4 4 4", "F F X"), {"field z", "TYPE X"});
  expect_error(header("binary", 2, "x y z", "4 4 4", "F F FF"), {"'FF'", "not I, U or F"});
  expect_error(header("binary", 2, "x y z", "4 4", "F F F"),
               {"FIELDS has 3 entries", "SIZE has 2"});
  expect_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 0 1\nWIDTH 1\nDATA ascii\n1 2 3\n",
               {"field y has COUNT 0"});
}

TEST_CASE("PCD: x, y and z are required with COUNT 1", "[pcd][malformed]") {
  expect_error(header("ascii", 1, "x y intensity", "4 4 4", "F F F") + "1 2 3\n",
               {"no field named z", "x, y and z are required"});
  expect_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 2 1 1\nWIDTH 1\nDATA ascii\n1 1 2 3\n",
               {"field x has COUNT 2, expected 1"});
}

TEST_CASE("PCD: WIDTH * HEIGHT must equal POINTS", "[pcd][malformed]") {
  expect_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 2\nPOINTS 5\nDATA ascii\n",
               {"line 6", "POINTS 5 does not match WIDTH * HEIGHT = 3 * 2"});
  expect_error(
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4294967296\nHEIGHT 4294967296\nDATA ascii\n",
      {"WIDTH * HEIGHT overflows"});
}

TEST_CASE("PCD binary: too few bytes for POINTS, checked before allocating", "[pcd][malformed]") {
  ByteBuilder b;
  b.text(header("binary", 2)).put(1.f).put(2.f).put(3.f).put(4.f);
  const auto e = expect_error(b.bytes, {"truncated binary data", "claims 2 points"});
  CHECK(e.position() == "byte " + std::to_string(header("binary", 2).size()));
  // A header claiming 10^15 points must fail on the size check, not on a huge allocation.
  ByteBuilder huge;
  huge.text(header("binary", 1000000000000000ull)).put(1.f).put(2.f).put(3.f);
  expect_error(huge.bytes, {"truncated binary data", "1000000000000000 points"});
}

TEST_CASE("PCD binary_compressed: every size field is checked", "[pcd][malformed]") {
  const Bytes data = io_test::lzf_literals_only(Bytes(24, 0));  // 2 points * 12 bytes of zeros
  // Sound file first, so the cases below fail for the stated reason only.
  io_test::TempDir dir;
  io_test::write_bytes(dir / "ok.pcd",
                       compressed(static_cast<std::uint32_t>(data.size()), 24, data));
  CHECK(ulc::io::read_pcd<ulc::PointCloud<float>>(dir / "ok.pcd").size() == 2);

  const std::size_t sizes_at = header("binary_compressed").size();
  expect_error(compressed(static_cast<std::uint32_t>(data.size()), 25, data),
               {"byte " + std::to_string(sizes_at + 4), "uncompressed size 25 does not match"});
  expect_error(compressed(static_cast<std::uint32_t>(data.size() + 1), 24, data),
               {"truncated compressed data"});
  // 1000 points * 12 bytes from 4 bytes of LZF: beyond what LZF can expand to.
  expect_error(compressed(4, 12000, Bytes{0, 0, 0, 0}, 1000), {"impossible for 4 bytes"});
  // Sizes cut short.
  ByteBuilder cut;
  cut.text(header("binary_compressed")).put<std::uint16_t>(7);
  expect_error(cut.bytes, {"truncated compressed size field"});
}

TEST_CASE("PCD binary_compressed: corrupt LZF data", "[pcd][malformed]") {
  // A back-reference as the very first chunk points before the start of the output.
  Bytes bad_ref = {0x20, 0x00};
  bad_ref.resize(4, 0);
  const std::size_t lzf_at = header("binary_compressed").size() + 8;
  const auto e = expect_error(compressed(4, 24, bad_ref), {"back-reference"});
  CHECK(e.position() == "byte " + std::to_string(lzf_at));
  // Valid LZF that decodes to fewer bytes than declared.
  const Bytes short_data = io_test::lzf_literals_only(Bytes(20, 0));
  expect_error(compressed(static_cast<std::uint32_t>(short_data.size()), 24, short_data),
               {"decodes to 20 bytes, header says 24"});
  // Literal run that overruns the compressed block.
  expect_error(compressed(3, 24, Bytes{31, 0, 0}), {"past the end of the compressed data"});
  // More output than declared.
  const Bytes long_data = io_test::lzf_literals_only(Bytes(30, 0));
  expect_error(compressed(static_cast<std::uint32_t>(long_data.size()), 24, long_data),
               {"more bytes than declared"});
}

TEST_CASE("PCD ascii: garbage numbers, wrong token counts, wrong line counts", "[pcd][malformed]") {
  const std::string h = header("ascii", 2);  // DATA is line 11
  expect_error(h + "1 2 3\n4 abc 6\n", {"line 13", "'abc' is not a number"});
  expect_error(h + "1 2 3\n4 5.5.5 6\n", {"line 13", "'5.5.5'"});
  expect_error(h + "1.00 2.00 3.00\n4 5\n", {"line 13", "expected 3 numbers, found 2"});
  expect_error(h + "1 2 3 4\n4 5 6\n", {"line 12", "expected 3 numbers, found 4"});
  expect_error(h + "1.00 2.00 3.00\n", {"truncated ascii data: found 1 of 2 points"});
  // Too few bytes for POINTS lines at all: caught by the size check before parsing.
  expect_error(h + "1 2\n", {"byte " + std::to_string(h.size()), "truncated ascii data"});
  expect_error(h + "1 2 3\n4 5 6\n7 8 9\n", {"line 14", "more data lines than POINTS 2"});
  expect_error(header("ascii", 1000000) + "1 2 3\n", {"truncated ascii data", "1000000 points"});
}
