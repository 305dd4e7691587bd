// Sequence folders: sorting, timestamps.txt, per-point and file-name times, errors.
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "ulc/io/sequence.hpp"

using io_test::TempDir;
using ulc::io::FrameTimeSource;
using ulc::io::Sequence;

namespace {

/// A frame whose first point's x identifies it; times optional.
ulc::PointCloud<double> frame_cloud(double id, std::vector<double> times = {}) {
  ulc::PointCloud<double> c;
  const std::size_t n = times.empty() ? 3 : times.size();
  for (std::size_t i = 0; i < n; ++i) c.points.emplace_back(id, static_cast<double>(i), 1.0);
  c.times = std::move(times);
  return c;
}

double first_x(const Sequence& seq, std::size_t i) {
  return seq.load_frame<ulc::PointCloud<double>>(i).cloud.points.at(0).x();
}

}  // namespace

TEST_CASE("sequence: frames sorted by file name, other files ignored, 10 Hz default",
          "[sequence]") {
  TempDir dir;
  const auto lidar = dir / "top";
  std::filesystem::create_directories(lidar / "sub.pcd");  // a folder, not a frame
  ulc::io::write_cloud(lidar / "000010.pcd", frame_cloud(10));
  ulc::io::write_cloud(lidar / "000002.pcd", frame_cloud(2));
  ulc::io::write_cloud(lidar / "000001.ply", frame_cloud(1));
  ulc::io::write_cloud(lidar / "000003.bin", frame_cloud(3));
  io_test::write_text(lidar / "notes.txt", "not a frame");

  const Sequence seq(lidar);
  CHECK(seq.name() == "top");
  REQUIRE(seq.size() == 4);
  CHECK(seq.time_source() == FrameTimeSource::nominal_rate);
  const std::vector<std::string> names = {"000001.ply", "000002.pcd", "000003.bin", "000010.pcd"};
  const std::vector<double> ids = {1, 2, 3, 10};
  for (std::size_t i = 0; i < 4; ++i) {
    CHECK(seq.frame(i).path.filename() == names[i]);
    CHECK(seq.frame(i).timestamp == Approx(0.1 * static_cast<double>(i)));
    CHECK(first_x(seq, i) == ids[i]);
  }
  const auto f = seq.load_frame<std::vector<Eigen::Vector3f>>(3);
  CHECK(f.cloud.size() == 3);
  CHECK(f.timestamp == Approx(0.3));
  CHECK(f.stats.format == "pcd");
  io_test::require_io_error([&] { seq.frame(4); }, {"frame index 4 out of range (4 frames)"});
}

TEST_CASE("sequence: timestamps.txt gives the frame times and must match the frame count",
          "[sequence]") {
  TempDir dir;
  for (int i = 0; i < 3; ++i)
    ulc::io::write_cloud(dir / ("00000" + std::to_string(i) + ".pcd"),
                         frame_cloud(i, {0.0, 0.0625}));

  io_test::write_text(dir / "timestamps.txt", "100.5\n100.6 \n  100.75\n\n");
  const Sequence seq(dir.path());
  CHECK(seq.time_source() == FrameTimeSource::timestamps_file);
  CHECK(seq.frame(0).timestamp == 100.5);
  CHECK(seq.frame(2).timestamp == 100.75);
  // Relative per-point times are returned as stored.
  CHECK(seq.load_frame<ulc::PointCloud<double>>(1).cloud.times == std::vector<double>{0.0, 0.0625});

  io_test::write_text(dir / "timestamps.txt", "100.5\n100.6\n");
  io_test::require_io_error([&] { Sequence s(dir.path()); },
                            {"timestamps.txt", "has 2 frame times but the folder has 3 frames"});
  io_test::write_text(dir / "timestamps.txt", "100.5\n100.6\n100.7\n100.8\n");
  io_test::require_io_error([&] { Sequence s(dir.path()); }, {"has 4 frame times"});
  io_test::write_text(dir / "timestamps.txt", "100.5\n1OO.6\n100.7\n");
  io_test::require_io_error([&] { Sequence s(dir.path()); },
                            {"timestamps.txt: line 2", "'1OO.6' is not one frame time"});
  io_test::write_text(dir / "timestamps.txt", "100.5\n100.6 100.65\n100.7\n");
  io_test::require_io_error([&] { Sequence s(dir.path()); }, {"line 2"});
  io_test::write_text(dir / "timestamps.txt", "100.5\n\n100.7\n100.8\n");
  io_test::require_io_error([&] { Sequence s(dir.path()); }, {"line 2", "empty line"});
}

TEST_CASE("sequence: absolute per-point times give the frame time and become relative",
          "[sequence]") {
  TempDir dir;
  const double t0 = 1645000000.25, t1 = 1645000000.35;
  ulc::io::write_cloud(dir / "a.pcd", frame_cloud(0, {t0 + 0.01, t0, t0 + 0.099}));
  ulc::io::write_cloud(dir / "b.ply", frame_cloud(1, {t1 + 0.05, t1 + 0.002, t1}));
  const Sequence seq(dir.path());
  CHECK(seq.time_source() == FrameTimeSource::point_times);
  CHECK(seq.frame(0).timestamp == t0);
  CHECK(seq.frame(1).timestamp == t1);
  const auto f0 = seq.load_frame<ulc::PointCloud<double>>(0);
  CHECK(f0.timestamp == t0);
  CHECK(f0.cloud.times == std::vector<double>{(t0 + 0.01) - t0, 0.0, (t0 + 0.099) - t0});
  const auto f1 = seq.load_frame<ulc::PointCloud<float>>(1);
  CHECK(f1.cloud.times[0] == Approx(0.05).margin(1e-6));
  CHECK(f1.cloud.times[2] == 0.0);

  // With timestamps.txt the times are relative to its frame times ...
  io_test::write_text(dir / "timestamps.txt", "1645000000.2\n1645000000.3\n");
  const Sequence with_file(dir.path());
  CHECK(with_file.time_source() == FrameTimeSource::timestamps_file);
  CHECK(with_file.load_frame<ulc::PointCloud<double>>(0).cloud.times[1] == t0 - 1645000000.2);
  // ... which must be the same clock.
  io_test::write_text(dir / "timestamps.txt", "0.0\n0.1\n");
  const Sequence other_clock(dir.path());
  io_test::require_io_error([&] { other_clock.load_frame<ulc::PointCloud<double>>(0); },
                            {"a.pcd", "different clocks"});
}

TEST_CASE("sequence: mixed absolute and relative per-point times are rejected", "[sequence]") {
  TempDir dir;
  ulc::io::write_cloud(dir / "0.pcd", frame_cloud(0, {1645000000.0, 1645000000.01}));
  ulc::io::write_cloud(dir / "1.pcd", frame_cloud(1, {0.0, 0.01}));
  io_test::require_io_error([&] { Sequence s(dir.path()); },
                            {"1.pcd", "has no absolute per-point times"});

  TempDir dir2;
  ulc::io::write_cloud(dir2 / "0.pcd", frame_cloud(0, {0.0, 0.01}));
  ulc::io::write_cloud(dir2 / "1.pcd", frame_cloud(1, {1645000000.0, 1645000000.01}));
  const Sequence seq(dir2.path());
  CHECK(seq.time_source() == FrameTimeSource::nominal_rate);
  io_test::require_io_error([&] { seq.load_frame<ulc::PointCloud<double>>(1); },
                            {"1.pcd", "cannot be mixed"});
}

TEST_CASE("sequence: frame times from file names", "[sequence]") {
  TempDir dir;
  ulc::io::write_cloud(dir / "1645000000.100.pcd", frame_cloud(0));
  ulc::io::write_cloud(dir / "1645000000.200.pcd", frame_cloud(1));
  const Sequence seq(dir.path());
  CHECK(seq.time_source() == FrameTimeSource::file_name);
  CHECK(seq.frame(0).timestamp == 1645000000.1);
  CHECK(seq.frame(1).timestamp == 1645000000.2);

  TempDir ns;
  ulc::io::write_cloud(ns / "1645000000100000000.bin", frame_cloud(0));
  ulc::io::write_cloud(ns / "1645000000150000000.bin", frame_cloud(1));
  const Sequence nseq(ns.path());
  CHECK(nseq.time_source() == FrameTimeSource::file_name);
  CHECK(nseq.frame(1).timestamp - nseq.frame(0).timestamp == Approx(0.05).margin(1e-6));

  // One name that is not a time: all frames fall back to 10 Hz.
  ulc::io::write_cloud(dir / "latest.pcd", frame_cloud(2));
  const Sequence fallback(dir.path());
  CHECK(fallback.time_source() == FrameTimeSource::nominal_rate);
  CHECK(fallback.frame(2).timestamp == Approx(0.2));
}

TEST_CASE("sequence: a single frame file is a sequence of one", "[sequence]") {
  TempDir dir;
  ulc::io::write_cloud(dir / "1645000000.5.pcd", frame_cloud(7));
  const Sequence by_name(dir / "1645000000.5.pcd");
  REQUIRE(by_name.size() == 1);
  CHECK(by_name.frame(0).timestamp == 1645000000.5);
  CHECK(first_x(by_name, 0) == 7);

  ulc::io::write_cloud(dir / "scan.ply", frame_cloud(8, {1645000000.0, 1645000000.04}));
  const Sequence by_points(dir / "scan.ply");
  CHECK(by_points.name() == "scan");
  CHECK(by_points.time_source() == FrameTimeSource::point_times);
  CHECK(by_points.load_frame<ulc::PointCloud<double>>(0).cloud.times[1] ==
        Approx(0.04).margin(1e-6));

  ulc::io::write_cloud(dir / "plain.bin", frame_cloud(9));
  CHECK(Sequence(dir / "plain.bin").frame(0).timestamp == 0.0);
  io_test::write_text(dir / "cloud.txt", "x");
  io_test::require_io_error([&] { Sequence s(dir / "cloud.txt"); },
                            {"unknown point-cloud file extension"});
}

TEST_CASE("sequence: missing folders, empty folders, lidar folders of a dataset", "[sequence]") {
  TempDir dir;
  io_test::require_io_error([&] { Sequence s(dir / "nothing"); },
                            {"nothing", "no such folder or file"});
  std::filesystem::create_directories(dir / "empty");
  io_test::write_text(dir / "empty" / "timestamps.txt", "0.0\n");
  io_test::require_io_error([&] { Sequence s(dir / "empty"); }, {"empty", "no frames"});

  io_test::require_io_error([&] { ulc::io::list_lidar_folders(dir.path()); }, {"no LiDAR folders"});
  std::filesystem::create_directories(dir / "top");
  std::filesystem::create_directories(dir / "left");
  ulc::io::write_cloud(dir / "top" / "000000.pcd", frame_cloud(0));
  ulc::io::write_cloud(dir / "left" / "000000.bin", frame_cloud(0));
  io_test::write_text(dir / "ground_truth.json", "{}");
  const auto lidars = ulc::io::list_lidar_folders(dir.path());
  REQUIRE(lidars.size() == 2);
  CHECK(lidars[0].filename() == "left");
  CHECK(lidars[1].filename() == "top");
  io_test::require_io_error([&] { ulc::io::list_lidar_folders(dir / "missing"); },
                            {"missing", "no such dataset folder"});
}
