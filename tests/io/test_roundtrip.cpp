// Every format and encoding: write then read gives the same points, intensities and times
// (exact for float data), for each kind of cloud type.
#include <catch2/catch.hpp>
#include <functional>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "ulc/io/cloud_file.hpp"

namespace {

namespace traits = ulc::traits;
using io_test::Sample;

template <typename Cloud>
Cloud make_cloud(const Sample& s) {
  using S = traits::scalar_t<Cloud>;
  Cloud c{};
  traits::resize(c, s.points.size());
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    traits::set_point(c, i, s.points[i].cast<S>());
    traits::set_intensity(c, i, static_cast<S>(s.intensities[i]));
    traits::set_time(c, i, static_cast<double>(s.times[i]));
  }
  return c;
}

template <typename Cloud>
void require_equal(const Cloud& a, const Cloud& b, bool with_time = true) {
  REQUIRE(traits::size(a) == traits::size(b));
  REQUIRE(traits::has_intensity(a) == traits::has_intensity(b));
  if (with_time) REQUIRE(traits::has_time(a) == traits::has_time(b));
  for (std::size_t i = 0; i < traits::size(a); ++i) {
    INFO("point " << i);
    REQUIRE(traits::point(a, i) == traits::point(b, i));
    REQUIRE(traits::intensity(a, i) == traits::intensity(b, i));
    if (with_time) REQUIRE(traits::time(a, i) == traits::time(b, i));
  }
}

struct Writer {
  std::string name;
  std::string file;
  std::function<void(const std::filesystem::path&)> write;
  bool stores_time;
};

template <typename Cloud>
std::vector<Writer> writers_for(const Cloud& c) {
  using namespace ulc::io;
  return {
      {"pcd binary", "a.pcd", [&](const auto& p) { write_pcd(p, c, PcdEncoding::binary); }, true},
      {"pcd compressed", "b.pcd",
       [&](const auto& p) { write_pcd(p, c, PcdEncoding::binary_compressed); }, true},
      {"pcd ascii", "c.pcd", [&](const auto& p) { write_pcd(p, c, PcdEncoding::ascii); }, true},
      {"ply little", "a.ply",
       [&](const auto& p) { write_ply(p, c, PlyFormat::binary_little_endian); }, true},
      {"ply big", "b.ply", [&](const auto& p) { write_ply(p, c, PlyFormat::binary_big_endian); },
       true},
      {"ply ascii", "c.ply", [&](const auto& p) { write_ply(p, c, PlyFormat::ascii); }, true},
      {"kitti", "a.bin", [&](const auto& p) { write_kitti_bin(p, c); }, false},
      {"write_cloud pcd", "d.pcd", [&](const auto& p) { write_cloud(p, c); }, true},
      {"write_cloud ply", "d.ply", [&](const auto& p) { write_cloud(p, c); }, true},
  };
}

}  // namespace

TEMPLATE_TEST_CASE("every format round-trips every cloud type exactly", "[roundtrip]",
                   ulc::PointCloud<float>, ulc::PointCloud<double>, std::vector<Eigen::Vector3f>,
                   std::vector<io_test::UserPoint>) {
  const TestType cloud = make_cloud<TestType>(io_test::make_sample(500));
  io_test::TempDir dir;
  for (const Writer& w : writers_for(cloud)) {
    INFO(w.name);
    const auto path = dir / w.file;
    w.write(path);
    ulc::io::ReadStats stats;
    const auto back = ulc::io::read_cloud<TestType>(path, &stats);
    CHECK(stats.points_read == 500);
    require_equal(cloud, back, w.stores_time);
    // Only the fields the cloud has are written.
    if (w.file != "a.bin") {
      CHECK(!stats.intensity_field.empty() == traits::has_intensity(cloud));
      CHECK(!stats.time_field.empty() == traits::has_time(cloud));
    }
  }
}

TEST_CASE("absolute per-point times survive PCD and PLY round trips exactly", "[roundtrip]") {
  ulc::PointCloud<double> cloud;
  for (int i = 0; i < 100; ++i) {
    cloud.points.emplace_back(i, -i, 0.5 * i);
    cloud.times.push_back(1645000000.0 + 1e-4 * i + 1e-7);
  }
  io_test::TempDir dir;
  for (const char* name : {"t.pcd", "t.ply"}) {
    INFO(name);
    ulc::io::write_cloud(dir / name, cloud);
    const auto back = ulc::io::read_cloud<ulc::PointCloud<double>>(dir / name);
    CHECK(back.times == cloud.times);
    CHECK(back.points == cloud.points);
  }
  ulc::io::write_pcd(dir / "c.pcd", cloud, ulc::io::PcdEncoding::binary_compressed);
  CHECK(ulc::io::read_pcd<ulc::PointCloud<double>>(dir / "c.pcd").times == cloud.times);
  ulc::io::write_pcd(dir / "a.pcd", cloud, ulc::io::PcdEncoding::ascii);
  CHECK(ulc::io::read_pcd<ulc::PointCloud<double>>(dir / "a.pcd").times == cloud.times);
}

TEST_CASE("an empty cloud round-trips in every format", "[roundtrip]") {
  const ulc::PointCloud<float> empty;
  io_test::TempDir dir;
  for (const Writer& w : writers_for(empty)) {
    INFO(w.name);
    w.write(dir / w.file);
    CHECK(ulc::io::read_cloud<ulc::PointCloud<float>>(dir / w.file).empty());
  }
}

TEST_CASE("PCD writer emits the documented header", "[roundtrip]") {
  ulc::PointCloud<float> cloud = make_cloud<ulc::PointCloud<float>>(io_test::make_sample(3));
  const auto bytes = ulc::io::encode_pcd(cloud, ulc::io::PcdEncoding::binary);
  const std::string text(bytes.begin(), bytes.end());
  CHECK(text.find("FIELDS x y z intensity t\nSIZE 4 4 4 4 4\nTYPE F F F F F\nCOUNT 1 1 1 1 1\n"
                  "WIDTH 3\nHEIGHT 1\n") != std::string::npos);
  CHECK(text.find("POINTS 3\nDATA binary\n") != std::string::npos);
  // Binary payload: 3 points * 20 bytes right after the header.
  CHECK(bytes.size() == text.find("DATA binary\n") + 12 + 60);
}

TEST_CASE("unknown extensions are rejected by read_cloud and write_cloud", "[roundtrip]") {
  io_test::TempDir dir;
  io_test::write_text(dir / "cloud.xyz", "1 2 3\n");
  io_test::require_io_error([&] { ulc::io::read_cloud<ulc::PointCloud<float>>(dir / "cloud.xyz"); },
                            {"cloud.xyz", "unknown point-cloud file extension '.xyz'"});
  io_test::require_io_error(
      [&] { ulc::io::write_cloud(dir / "cloud.las", ulc::PointCloud<float>{}); },
      {"cloud.las", "expected .pcd, .ply or .bin"});
  // Extensions are case-insensitive.
  ulc::io::write_cloud(dir / "UPPER.PCD",
                       make_cloud<ulc::PointCloud<float>>(io_test::make_sample(4)));
  CHECK(ulc::io::read_cloud<ulc::PointCloud<float>>(dir / "UPPER.PCD").size() == 4);
}
