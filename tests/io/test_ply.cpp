// PLY reading from hand-written bytes (ascii, big and little endian) and malformed PLY files.
#include <catch2/catch.hpp>
#include <cstdint>
#include <limits>
#include <string>

#include "io_test_util.hpp"
#include "ulc/io/ply.hpp"

using io_test::ByteBuilder;
using io_test::Bytes;
using ulc::io::DecodedCloud;
using ulc::io::ReadStats;

namespace {

// A `face` element with a list property comes first and must be skipped; the vertex element has
// mixed types, a list of its own, an integer-nanosecond time and elements after it.
const std::string kHeaderBody =
    "comment hand written\n"
    "obj_info test\n"
    "element face 2\n"
    "property list uchar int vertex_indices\n"
    "property uchar flags\n"
    "element vertex 3\n"
    "property double x\n"
    "property float y\n"
    "property int16 z\n"
    "property list uint8 float32 extra\n"
    "property uchar intensity\n"
    "property uint offset_time\n"
    "element edge 1\n"
    "property int vertex1\n"
    "end_header\n";

void check_vertices(const DecodedCloud& c, const ReadStats& st) {
  REQUIRE(c.size() == 2);  // the middle vertex has x = NaN
  CHECK(c.points[0] == Eigen::Vector3d(0.125, -2.5f, -300));
  CHECK(c.points[1] == Eigen::Vector3d(1e10, 7.75f, 32767));
  CHECK(c.intensities == std::vector<double>{255, 3});
  REQUIRE(c.times.size() == 2);
  CHECK(c.times[0] == Approx(0.05).epsilon(1e-12));  // 50,000,000 ns
  CHECK(c.times[1] == 0.0);
  CHECK(st.format == "ply");
  CHECK(st.fields == std::vector<std::string>{"x", "y", "z", "extra", "intensity", "offset_time"});
  CHECK(st.time_field == "offset_time");
  CHECK(st.time_scale == 1e-9);
  CHECK(st.points_in_file == 3);
  CHECK(st.points_dropped_nonfinite == 1);
}

template <bool BigEndian>
Bytes binary_ply() {
  ByteBuilder b;
  b.text(std::string("ply\nformat ") + (BigEndian ? "binary_big_endian" : "binary_little_endian") +
         " 1.0\n" + kHeaderBody);
  auto put = [&](auto v) {
    if (BigEndian)
      b.put_be(v);
    else
      b.put(v);
  };
  // faces: list of 3 and of 4 indices, then flags
  put(std::uint8_t{3}), put(std::int32_t{0}), put(std::int32_t{1}), put(std::int32_t{2});
  put(std::uint8_t{1});
  put(std::uint8_t{4});
  for (std::int32_t i = 0; i < 4; ++i) put(i);
  put(std::uint8_t{0});
  // vertices: x y z extra[] intensity offset_time
  put(0.125), put(-2.5f), put(std::int16_t{-300}), put(std::uint8_t{2}), put(1.f), put(2.f);
  put(std::uint8_t{255}), put(std::uint32_t{50000000});
  put(std::numeric_limits<double>::quiet_NaN()), put(0.f), put(std::int16_t{0});
  put(std::uint8_t{0}), put(std::uint8_t{9}), put(std::uint32_t{1});
  put(1e10), put(7.75f), put(std::int16_t{32767}), put(std::uint8_t{1}), put(5.f);
  put(std::uint8_t{3}), put(std::uint32_t{0});
  // edge element after the vertices: never read, so its garbage does not matter
  b.text("garbage");
  return b.bytes;
}

const std::string kAsciiPly = "ply\nformat ascii 1.0\n" + kHeaderBody +
                              "3 0 1 2 1\n"
                              "4 0 1 2 3 0\n"
                              "0.125 -2.5 -300 2 1 2 255 50000000\n"
                              "nan 0 0 0 9 1\n"
                              "1e10 7.75 32767 1 5 3 0\n"
                              "this edge line is never parsed\n";

std::string simple_header(const std::string& format, std::size_t n) {
  return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(n) +
         "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
}

void expect_ply_error(const Bytes& bytes, std::initializer_list<std::string> parts) {
  io_test::TempDir dir;
  const auto path = dir / "bad.ply";
  io_test::write_bytes(path, bytes);
  const auto e =
      io_test::require_io_error([&] { ulc::io::read_ply<ulc::PointCloud<float>>(path); }, parts);
  CHECK(e.file() == path.string());
}
void expect_ply_error(const std::string& text, std::initializer_list<std::string> parts) {
  expect_ply_error(io_test::to_bytes(text), parts);
}

}  // namespace

TEST_CASE("PLY binary big endian: elements before vertex are skipped, lists included", "[ply]") {
  ReadStats st;
  check_vertices(ulc::io::decode_ply(binary_ply<true>(), "big.ply", &st), st);
  CHECK(st.encoding == "binary_big_endian");
}

TEST_CASE("PLY binary little endian with the same content", "[ply]") {
  ReadStats st;
  check_vertices(ulc::io::decode_ply(binary_ply<false>(), "little.ply", &st), st);
  CHECK(st.encoding == "binary_little_endian");
}

TEST_CASE("PLY ascii with the same content", "[ply]") {
  ReadStats st;
  check_vertices(ulc::io::decode_ply(io_test::to_bytes(kAsciiPly), "ascii.ply", &st), st);
  CHECK(st.encoding == "ascii");
}

TEST_CASE("PLY writer: big endian bytes are really big endian", "[ply]") {
  std::vector<Eigen::Vector3f> cloud = {{1.f, -2.f, 0.5f}};
  const Bytes bytes = ulc::io::encode_ply(cloud, ulc::io::PlyFormat::binary_big_endian);
  const std::string text(bytes.begin(), bytes.end());
  const std::size_t data = text.find("end_header\n") + 11;
  REQUIRE(bytes.size() == data + 12);
  // 1.0f = 3f 80 00 00, -2.0f = c0 00 00 00, 0.5f = 3f 00 00 00
  const Bytes expected = {0x3f, 0x80, 0, 0, 0xc0, 0, 0, 0, 0x3f, 0, 0, 0};
  CHECK(Bytes(bytes.begin() + static_cast<std::ptrdiff_t>(data), bytes.end()) == expected);
  CHECK(text.find("format binary_big_endian 1.0\n") != std::string::npos);
  CHECK(text.find("element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                  "end_header\n") != std::string::npos);
}

TEST_CASE("PLY: malformed headers", "[ply][malformed]") {
  expect_ply_error(Bytes{}, {"empty file"});
  expect_ply_error("PLY\nformat ascii 1.0\n", {"line 1", "not a PLY file"});
  expect_ply_error("ply\nelement vertex 1\nproperty float x\nend_header\n", {"missing format"});
  expect_ply_error("ply\nformat binary_middle_endian 1.0\nend_header\n",
                   {"line 2", "unknown PLY format"});
  expect_ply_error("ply\nformat ascii 2.0\nend_header\n", {"line 2", "unsupported PLY version"});
  expect_ply_error("ply\nformat ascii 1.0\nproperty float x\nend_header\n",
                   {"line 3", "property before any element"});
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float16 x\nend_header\n",
                   {"line 4", "unknown property type 'float16'"});
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int x\nend_header\n",
      {"line 4", "list count type 'float' is not an integer type"});
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex x\n", {"line 3", "element line"});
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
                   {"missing end_header"});
  expect_ply_error("ply\nformat ascii 1.0\nwhatever\nend_header\n",
                   {"line 3", "unknown header line"});
  expect_ply_error("ply\nformat ascii 1.0\nelement face 1\nproperty int a\nend_header\n1\n",
                   {"line 5", "no vertex element"});
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float z\nend_header\n",
      {"line 3", "no field named y"});
}

TEST_CASE("PLY: malformed binary data", "[ply][malformed]") {
  ByteBuilder cut;
  cut.text(simple_header("binary_little_endian", 2)).put(1.f).put(2.f).put(3.f).put(4.f);
  expect_ply_error(cut.bytes, {"truncated vertex data", "claims 2 vertices"});
  ByteBuilder huge;
  huge.text(simple_header("binary_little_endian", 4000000000u)).put(1.f).put(2.f).put(3.f);
  expect_ply_error(huge.bytes, {"truncated vertex data", "4000000000 vertices"});
  // A list before the vertex element claims more items than the file holds.
  ByteBuilder list;
  list.text(
      "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uint int idx\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
  const std::size_t list_at = list.bytes.size();
  list.put(std::uint32_t{1000000}).put(1.f).put(2.f).put(3.f);
  expect_ply_error(list.bytes, {"byte " + std::to_string(list_at), "truncated list property idx"});
  // A negative list count.
  ByteBuilder negative;
  negative.text(
      "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list char int idx\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
  negative.put(std::int8_t{-1}).put(1.f).put(2.f).put(3.f);
  expect_ply_error(negative.bytes, {"negative count in list property idx"});
}

TEST_CASE("PLY: malformed ascii data", "[ply][malformed]") {
  const std::string h = simple_header("ascii", 2);  // end_header is line 7
  expect_ply_error(h + "1 2 3\n4 x 6\n", {"line 9", "'x' is not a number"});
  expect_ply_error(h + "1.00 2.00 3.00\n4 5\n", {"line 9", "too few values"});
  expect_ply_error(h + "1 2 3 4\n4 5 6\n", {"line 8", "expected 3 values", "found 4"});
  expect_ply_error(h + "1.00 2.00 3.00\n", {"truncated ascii data", "needs 2 records"});
  expect_ply_error(simple_header("ascii", 1000000) + "1 2 3\n", {"truncated ascii data"});
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int idx\nelement vertex 1\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n5 1 2\n1 2 3\n",
      {"line 10", "claims 5 items"});
}
