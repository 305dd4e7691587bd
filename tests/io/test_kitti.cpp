// KITTI .bin: known bytes, size errors, empty files.
#include <catch2/catch.hpp>
#include <limits>

#include "io_test_util.hpp"
#include "ulc/io/kitti_bin.hpp"

using io_test::ByteBuilder;
using io_test::Bytes;

TEST_CASE("KITTI .bin: float32 x y z intensity records", "[kitti]") {
  ByteBuilder b;
  b.put(1.5f).put(-2.f).put(0.25f).put(0.75f);
  b.put(std::numeric_limits<float>::infinity()).put(0.f).put(0.f).put(1.f);
  b.put(10.f).put(20.f).put(-30.f).put(0.f);
  ulc::io::ReadStats st;
  const auto c = ulc::io::decode_kitti_bin(b.bytes, "000000.bin", &st);
  REQUIRE(c.size() == 2);
  CHECK(c.points[0] == Eigen::Vector3d(1.5, -2, 0.25));
  CHECK(c.points[1] == Eigen::Vector3d(10, 20, -30));
  CHECK(c.intensities == std::vector<double>{0.75, 0});
  CHECK_FALSE(c.has_times());
  CHECK(st.points_in_file == 3);
  CHECK(st.points_dropped_nonfinite == 1);
  CHECK(st.format == "kitti_bin");
}

TEST_CASE("KITTI .bin: a size that is not a multiple of 16 names the size", "[kitti][malformed]") {
  io_test::TempDir dir;
  const auto path = dir / "000001.bin";
  io_test::write_bytes(path, Bytes(37, 0));
  const auto e =
      io_test::require_io_error([&] { ulc::io::read_kitti_bin<ulc::PointCloud<float>>(path); },
                                {"000001.bin", "file size 37 bytes is not a multiple of 16"});
  CHECK(e.position() == "byte 32");
}

TEST_CASE("KITTI .bin: an empty file is an empty cloud; writing stores intensity 0 if absent",
          "[kitti]") {
  io_test::TempDir dir;
  io_test::write_bytes(dir / "e.bin", Bytes{});
  CHECK(ulc::io::read_kitti_bin<ulc::PointCloud<float>>(dir / "e.bin").empty());

  const std::vector<Eigen::Vector3d> cloud = {{1, 2, 3}};
  const Bytes bytes = ulc::io::encode_kitti_bin(cloud);
  ByteBuilder expected;
  expected.put(1.f).put(2.f).put(3.f).put(0.f);
  CHECK(bytes == expected.bytes);
}
