// PCD reading from hand-written bytes: every DATA kind, mixed field types, multi-count fields.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "ulc/io/pcd.hpp"

using io_test::ByteBuilder;
using io_test::Bytes;
using ulc::io::DecodedCloud;
using ulc::io::ReadStats;

namespace {

// Three points in every encoding: x y z F4, intensity F4, ring U2, desc F4 x3, timestamp F8.
// The second point has x = NaN and must be dropped.
struct MixedPoint {
  float x, y, z, intensity;
  std::uint16_t ring;
  float desc[3];
  double timestamp;
};
const MixedPoint kMixed[3] = {
    {1.5f, -2.25f, 3.f, 10.f, 7, {0.5f, 0.25f, 0.125f}, 1645000000.125},
    {std::numeric_limits<float>::quiet_NaN(), 0.f, 0.f, 11.f, 8, {1, 2, 3}, 1645000000.25},
    {-4.f, 5.5f, 0.75f, 12.f, 9, {4, 5, 6}, 1645000000.375},
};

std::string mixed_header(const std::string& data) {
  return "# .PCD v0.7 - Point Cloud Data file format\n"
         "VERSION 0.7\n"
         "FIELDS x y z intensity ring desc timestamp\n"
         "SIZE 4 4 4 4 2 4 8\n"
         "TYPE F F F F U F F\n"
         "COUNT 1 1 1 1 1 3 1\n"
         "WIDTH 3\n"
         "HEIGHT 1\n"
         "VIEWPOINT 0 0 0 1 0 0 0\n"
         "POINTS 3\n"
         "DATA " +
         data + "\n";
}

Bytes mixed_ascii() {
  return io_test::to_bytes(mixed_header("ascii") +
                           "1.5 -2.25 3 10 7 0.5 0.25 0.125 1645000000.125\n"
                           "nan 0 0 11 8 1 2 3 1645000000.25\n"
                           "-4 5.5 0.75 12 9 4 5 6 1645000000.375\n");
}

Bytes mixed_binary() {
  ByteBuilder b;
  b.text(mixed_header("binary"));
  for (const MixedPoint& p : kMixed)
    b.put(p.x)
        .put(p.y)
        .put(p.z)
        .put(p.intensity)
        .put(p.ring)
        .put(p.desc[0])
        .put(p.desc[1])
        .put(p.desc[2])
        .put(p.timestamp);
  return b.bytes;
}

// Field-major layout, LZF made of literal runs only (independent of our encoder).
Bytes mixed_compressed_raw() {
  ByteBuilder raw;
  for (const MixedPoint& p : kMixed) raw.put(p.x);
  for (const MixedPoint& p : kMixed) raw.put(p.y);
  for (const MixedPoint& p : kMixed) raw.put(p.z);
  for (const MixedPoint& p : kMixed) raw.put(p.intensity);
  for (const MixedPoint& p : kMixed) raw.put(p.ring);
  for (const MixedPoint& p : kMixed) raw.put(p.desc[0]).put(p.desc[1]).put(p.desc[2]);
  for (const MixedPoint& p : kMixed) raw.put(p.timestamp);
  return raw.bytes;
}

Bytes mixed_compressed() {
  const Bytes raw = mixed_compressed_raw();
  const Bytes lzf = io_test::lzf_literals_only(raw);
  ByteBuilder b;
  b.text(mixed_header("binary_compressed"));
  b.put(static_cast<std::uint32_t>(lzf.size())).put(static_cast<std::uint32_t>(raw.size()));
  b.raw(lzf);
  return b.bytes;
}

void check_mixed(const DecodedCloud& c, const ReadStats& st) {
  REQUIRE(c.size() == 2);
  CHECK(c.points[0] == Eigen::Vector3d(1.5, -2.25, 3));
  CHECK(c.points[1] == Eigen::Vector3d(-4, 5.5, 0.75));
  REQUIRE(c.has_intensities());
  CHECK(c.intensities == std::vector<double>{10, 12});
  REQUIRE(c.has_times());
  CHECK(c.times == std::vector<double>{1645000000.125, 1645000000.375});  // kept absolute
  CHECK(st.format == "pcd");
  CHECK(st.fields ==
        std::vector<std::string>{"x", "y", "z", "intensity", "ring", "desc", "timestamp"});
  CHECK(st.intensity_field == "intensity");
  CHECK(st.time_field == "timestamp");
  CHECK(st.time_scale == 1.0);
  CHECK(st.points_in_file == 3);
  CHECK(st.points_read == 2);
  CHECK(st.points_dropped_nonfinite == 1);
  CHECK(st.width == 3);
  CHECK(st.height == 1);
}

// Header without COUNT (it defaults to 1 for every field).
std::string xyz_header(const std::string& fields, const std::string& sizes,
                       const std::string& types, std::size_t width, std::size_t height,
                       const std::string& data) {
  return "VERSION 0.7\nFIELDS " + fields + "\nSIZE " + sizes + "\nTYPE " + types + "\nWIDTH " +
         std::to_string(width) + "\nHEIGHT " + std::to_string(height) + "\nPOINTS " +
         std::to_string(width * height) + "\nDATA " + data + "\n";
}

}  // namespace

TEST_CASE("PCD ascii with mixed field types and a COUNT 3 field", "[pcd]") {
  ReadStats st;
  const DecodedCloud c = ulc::io::decode_pcd(mixed_ascii(), "mixed.pcd", &st);
  check_mixed(c, st);
  CHECK(st.encoding == "ascii");
}

TEST_CASE("PCD binary with mixed field types and a COUNT 3 field", "[pcd]") {
  ReadStats st;
  const DecodedCloud c = ulc::io::decode_pcd(mixed_binary(), "mixed.pcd", &st);
  check_mixed(c, st);
  CHECK(st.encoding == "binary");
}

TEST_CASE("PCD binary_compressed with mixed field types and a COUNT 3 field", "[pcd]") {
  ReadStats st;
  const DecodedCloud c = ulc::io::decode_pcd(mixed_compressed(), "mixed.pcd", &st);
  check_mixed(c, st);
  CHECK(st.encoding == "binary_compressed");
}

TEST_CASE("PCD binary_compressed also reads back-references from a real encoder", "[pcd]") {
  const Bytes raw = mixed_compressed_raw();
  const Bytes lzf = ulc::io::lzf_compress(raw);
  ByteBuilder b;
  b.text(mixed_header("binary_compressed"));
  b.put(static_cast<std::uint32_t>(lzf.size())).put(static_cast<std::uint32_t>(raw.size()));
  b.raw(lzf);
  ReadStats st;
  check_mixed(ulc::io::decode_pcd(b.bytes, "mixed.pcd", &st), st);
}

TEST_CASE("PCD coordinates of any numeric type are converted", "[pcd]") {
  ByteBuilder b;
  b.text(xyz_header("y pad x z", "4 1 8 2", "I U F U", 2, 1, "binary"));
  b.put<std::int32_t>(-7).put<std::uint8_t>(200).put<double>(0.1).put<std::uint16_t>(65535);
  b.put<std::int32_t>(123456).put<std::uint8_t>(0).put<double>(-1e300).put<std::uint16_t>(0);
  ReadStats st;
  const DecodedCloud c = ulc::io::decode_pcd(b.bytes, "types.pcd", &st);
  REQUIRE(c.size() == 2);
  CHECK(c.points[0] == Eigen::Vector3d(0.1, -7, 65535));
  CHECK(c.points[1] == Eigen::Vector3d(-1e300, 123456, 0));
  CHECK_FALSE(c.has_intensities());
  CHECK_FALSE(c.has_times());
  CHECK(st.time_field.empty());
}

TEST_CASE("PCD time field: preference order and integer nanoseconds", "[pcd]") {
  SECTION("t wins over timestamp and time") {
    ByteBuilder b;
    b.text(xyz_header("x y z timestamp time t", "4 4 4 8 4 4", "F F F F F F", 1, 1, "binary"));
    b.put(1.f).put(2.f).put(3.f).put(100.0).put(200.f).put(0.25f);
    ReadStats st;
    const DecodedCloud c = ulc::io::decode_pcd(b.bytes, "t.pcd", &st);
    CHECK(st.time_field == "t");
    CHECK(c.times == std::vector<double>{0.25});
  }
  SECTION("time wins over timestamp") {
    ByteBuilder b;
    b.text(xyz_header("x y z timestamp time", "4 4 4 8 4", "F F F F F", 1, 1, "binary"));
    b.put(1.f).put(2.f).put(3.f).put(100.0).put(0.5f);
    ReadStats st;
    CHECK(ulc::io::decode_pcd(b.bytes, "t.pcd", &st).times == std::vector<double>{0.5});
    CHECK(st.time_field == "time");
  }
  SECTION("Livox offset_time uint32 nanoseconds become seconds") {
    ByteBuilder b;
    b.text(xyz_header("x y z offset_time", "4 4 4 4", "F F F U", 2, 1, "binary"));
    b.put(1.f).put(2.f).put(3.f).put<std::uint32_t>(0);
    b.put(1.f).put(2.f).put(3.f).put<std::uint32_t>(99999999);
    ReadStats st;
    const DecodedCloud c = ulc::io::decode_pcd(b.bytes, "livox.pcd", &st);
    CHECK(st.time_field == "offset_time");
    CHECK(st.time_scale == 1e-9);
    REQUIRE(c.times.size() == 2);
    CHECK(c.times[0] == 0.0);
    CHECK(c.times[1] == Approx(0.099999999).epsilon(1e-12));
  }
  SECTION("a multi-count time field is ignored") {
    ByteBuilder b;
    b.text(
        "FIELDS x y z t\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 2\nWIDTH 1\nHEIGHT 1\n"
        "POINTS 1\nDATA binary\n");
    b.put(1.f).put(2.f).put(3.f).put(0.1f).put(0.2f);
    ReadStats st;
    CHECK_FALSE(ulc::io::decode_pcd(b.bytes, "t.pcd", &st).has_times());
    CHECK(st.time_field.empty());
  }
}

TEST_CASE("PCD organised cloud: NaN points are dropped and counted", "[pcd]") {
  ByteBuilder b;
  b.text(xyz_header("x y z", "4 4 4", "F F F", 2, 2, "binary"));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  b.put(1.f).put(1.f).put(1.f);
  b.put(nan).put(nan).put(nan);
  b.put(2.f).put(-inf).put(2.f);
  b.put(3.f).put(3.f).put(3.f);
  ReadStats st;
  const DecodedCloud c = ulc::io::decode_pcd(b.bytes, "organised.pcd", &st);
  REQUIRE(c.size() == 2);
  CHECK(c.points[0] == Eigen::Vector3d(1, 1, 1));
  CHECK(c.points[1] == Eigen::Vector3d(3, 3, 3));
  CHECK(st.width == 2);
  CHECK(st.height == 2);
  CHECK(st.points_in_file == 4);
  CHECK(st.points_read == 2);
  CHECK(st.points_dropped_nonfinite == 2);
}

TEST_CASE("PCD ascii: comments, CRLF lines, blank lines and no final newline", "[pcd]") {
  const std::string text =
      "# comment\r\nVERSION .7\r\nFIELDS x y z intensity\r\nSIZE 4 4 4 4\r\nTYPE F F F F\r\n"
      "COUNT 1 1 1 1\r\nWIDTH 2\r\nHEIGHT 1\r\nPOINTS 2\r\nDATA ascii\r\n"
      "1e-3 +2 -3.5e2 0\r\n\r\n  4\t5 6 255";
  const DecodedCloud c = ulc::io::decode_pcd(io_test::to_bytes(text), "crlf.pcd");
  REQUIRE(c.size() == 2);
  CHECK(c.points[0] == Eigen::Vector3d(double(1e-3f), 2, -350));  // F4: read as float
  CHECK(c.points[1] == Eigen::Vector3d(4, 5, 6));
  CHECK(c.intensities == std::vector<double>{0, 255});
}

TEST_CASE("PCD with zero points reads as an empty cloud in every encoding", "[pcd]") {
  for (const char* kind : {"ascii", "binary", "binary_compressed"}) {
    INFO(kind);
    const DecodedCloud c = ulc::io::decode_pcd(
        io_test::to_bytes(xyz_header("x y z", "4 4 4", "F F F", 0, 1, kind)), "empty_cloud.pcd");
    CHECK(c.size() == 0);
  }
}

TEST_CASE("PCD read_pcd fills every built-in cloud type", "[pcd]") {
  io_test::TempDir dir;
  const auto path = dir / "mixed.pcd";
  io_test::write_bytes(path, mixed_binary());
  const auto soa = ulc::io::read_pcd<ulc::PointCloud<double>>(path);
  REQUIRE(soa.size() == 2);
  CHECK(soa.points[1] == Eigen::Vector3d(-4, 5.5, 0.75));
  CHECK(soa.intensities == std::vector<double>{10, 12});
  CHECK(soa.times == std::vector<double>{1645000000.125, 1645000000.375});
  const auto vec = ulc::io::read_pcd<std::vector<Eigen::Vector3f>>(path);
  REQUIRE(vec.size() == 2);
  CHECK(vec[0] == Eigen::Vector3f(1.5f, -2.25f, 3.f));
  const auto mat = ulc::io::read_pcd<Eigen::MatrixX3d>(path);
  REQUIRE(mat.rows() == 2);
  CHECK(mat(1, 2) == 0.75);
  const auto users = ulc::io::read_pcd<std::vector<io_test::UserPoint>>(path);
  REQUIRE(users.size() == 2);
  CHECK(users[1].intensity == 12.f);
  CHECK(users[1].x == -4.f);
}
