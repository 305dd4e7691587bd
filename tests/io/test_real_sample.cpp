// The real croon_0003 sample (binary_compressed, x y z intensity ring timestamp; F4 F4 F4 F4 U2
// F8). Skips cleanly when ../shared is absent.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <string>

#include "io_test_util.hpp"
#include "test_paths.hpp"
#include "ulc/io/pcd.hpp"
#include "ulc/io/sequence.hpp"

namespace {

/// The POINTS value read straight from the header text, independently of the reader.
std::size_t header_points(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("POINTS ", 0) == 0) return std::stoul(line.substr(7));
  return 0;
}

}  // namespace

TEST_CASE("real sample: all three frames load with the header's point counts", "[real]") {
  const auto dir = ulc_test::croon_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "croon_0003 sample not found next to the checkout");
  struct Expect {
    const char* name;
    std::size_t points;
  };
  for (const Expect& e : {Expect{"top", 87937}, Expect{"left", 9877}, Expect{"right", 10194}}) {
    INFO(e.name);
    const auto path = dir / (std::string(e.name) + ".pcd");
    CHECK(header_points(path) == e.points);
    ulc::io::ReadStats st;
    const auto cloud = ulc::io::read_pcd<ulc::PointCloud<double>>(path, &st);
    CHECK(st.encoding == "binary_compressed");
    CHECK(st.points_in_file == e.points);
    CHECK(st.points_read + st.points_dropped_nonfinite == e.points);
    CHECK(st.points_read == cloud.size());
    CHECK(cloud.size() > e.points / 2);
    CHECK(st.fields == std::vector<std::string>{"x", "y", "z", "intensity", "ring", "timestamp"});
    CHECK(st.time_field == "timestamp");
    REQUIRE(cloud.has_times());
    REQUIRE(cloud.has_intensities());
    bool finite = true;
    double t_min = cloud.times[0], t_max = cloud.times[0];
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      finite = finite && cloud.points[i].allFinite();
      t_min = std::min(t_min, cloud.times[i]);
      t_max = std::max(t_max, cloud.times[i]);
    }
    CHECK(finite);
    CHECK(t_min > 1.6e9);  // absolute Unix seconds, kept as read
    CHECK(t_max - t_min <= 0.2);
  }
}

TEST_CASE("real sample: a frame file as a sequence gets relative times", "[real]") {
  const auto dir = ulc_test::croon_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "croon_0003 sample not found next to the checkout");
  const ulc::io::Sequence seq(dir / "left.pcd");
  CHECK(seq.time_source() == ulc::io::FrameTimeSource::point_times);
  const auto frame = seq.load_frame<ulc::PointCloud<float>>(0);
  CHECK(frame.timestamp > 1.6e9);
  double t_min = 1e9, t_max = -1e9;
  for (double t : frame.cloud.times) {
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
  CHECK(t_min == 0.0);
  CHECK(t_max <= 0.2);
}

TEST_CASE("real sample: re-encoding with our LZF writer keeps every value", "[real]") {
  const auto dir = ulc_test::croon_dir();
  ULC_SKIP_UNLESS(!dir.empty(), "croon_0003 sample not found next to the checkout");
  const auto original = ulc::io::read_pcd<ulc::PointCloud<float>>(dir / "right.pcd");
  ulc::PointCloud<float> relative = original;
  for (double& t : relative.times) t -= original.times[0];  // keep times float-exact below
  for (double& t : relative.times) t = static_cast<float>(t);
  io_test::TempDir tmp;
  ulc::io::write_pcd(tmp / "r.pcd", relative, ulc::io::PcdEncoding::binary_compressed);
  const auto back = ulc::io::read_pcd<ulc::PointCloud<float>>(tmp / "r.pcd");
  CHECK(back.points == relative.points);
  CHECK(back.intensities == relative.intensities);
  CHECK(back.times == relative.times);
  CHECK(std::filesystem::file_size(tmp / "r.pcd") <
        original.size() * 20);  // compressed below the raw 20 bytes per point
}
