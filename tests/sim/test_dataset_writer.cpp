// The dataset folder: exact layout and bytes, streaming equals in-memory, stale frames removed,
// and determinism: same seed -> byte-identical files, with 1 or 2 threads.
#include <tbb/task_arena.h>

#include <unistd.h>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "ulc/io/ground_truth.hpp"
#include "ulc/io/pcd_read.hpp"
#include "ulc/sim/dataset_writer.hpp"

using namespace ulc::sim;
namespace fs = std::filesystem;

namespace {

/// A fresh, empty temporary folder, removed when the test ends.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& tag) {
    path = fs::temp_directory_path() / ("ulc_sim_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> lines(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

/// Every regular file under dir, relative path -> bytes.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = read_all(e.path());
  return files;
}

}  // namespace

TEST_CASE("dataset folder: layout, PCD bytes, timestamps, trajectory, ground truth",
          "[sim][writer]") {
  TempDir tmp("layout");
  SimulationOptions o;
  o.seconds = 0.3;
  o.seed = 5;
  o.decimation = 8;
  o.target_clock_offset_s = 0.02;
  const ScenarioSpec spec = *scenario("32-16");
  // A stale frame from a longer earlier run and an unrelated file.
  fs::create_directories(tmp.path / "lidar16");
  { std::ofstream(tmp.path / "lidar16" / "000099.pcd") << "old"; }
  { std::ofstream(tmp.path / "notes.txt") << "keep me"; }

  const SimulationResult streamed = simulate_to_directory(tmp.path, spec, o);
  REQUIRE(streamed.ok());
  o.keep_frames = true;
  const SimulationResult memory = simulate(spec, o);
  REQUIRE(memory.ok());

  CHECK_FALSE(fs::exists(tmp.path / "lidar16" / "000099.pcd"));
  CHECK(read_all(tmp.path / "notes.txt") == "keep me");
  for (const LidarRecording& l : memory.dataset.lidars) {
    INFO(l.name);
    REQUIRE(l.frames.size() == 3);
    // timestamps.txt: one "%.9f" line per frame, in the LiDAR's own clock.
    const auto ts = lines(tmp.path / l.name / "timestamps.txt");
    REQUIRE(ts.size() == 3);
    CHECK(l.timestamps[0] > 0.0);  // recording starts 1 s into the drive
    for (std::size_t k = 0; k < 3; ++k) {
      char expect[64];
      std::snprintf(expect, sizeof(expect), "%.9f", l.timestamps[k]);
      CHECK(ts[k] == expect);
      if (k > 0) CHECK(l.timestamps[k] - l.timestamps[k - 1] == Approx(0.1).epsilon(1e-12));
    }
    for (std::size_t k = 0; k < 3; ++k) {
      const ulc::PointCloud<float>& cloud = l.frames[k];
      const fs::path file = tmp.path / l.name / frame_file_name(k);
      const std::string bytes = read_all(file);
      const std::string n = std::to_string(cloud.size());
      const std::string header =
          "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity t\n"
          "SIZE 4 4 4 4 4\nTYPE F F F F F\nCOUNT 1 1 1 1 1\nWIDTH " +
          n + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\nDATA binary\n";
      REQUIRE(bytes.size() == header.size() + 20 * cloud.size());
      CHECK(bytes.compare(0, header.size(), header) == 0);
      // The stored record of point 7: x y z intensity t as little-endian float32.
      float rec[5];
      std::memcpy(rec, bytes.data() + header.size() + 20 * 7, sizeof(rec));
      CHECK(rec[0] == cloud.points[7].x());
      CHECK(rec[2] == cloud.points[7].z());
      CHECK(rec[3] == cloud.intensities[7]);
      CHECK(rec[4] == static_cast<float>(cloud.times[7]));
      // Streaming wrote exactly what the in-memory run holds.
      const auto back = ulc::io::read_pcd<ulc::PointCloud<float>>(file);
      REQUIRE(back.size() == cloud.size());
      CHECK(back.points == cloud.points);
    }
  }
  // trajectory.txt: t x y z qw qx qy qz, unit quaternions, 100 Hz from t = 0.
  const auto traj = lines(tmp.path / "trajectory.txt");
  REQUIRE(traj.size() == memory.dataset.trajectory.size());
  for (std::size_t i = 0; i < traj.size(); i += 7) {
    std::istringstream row(traj[i]);
    double v[8];
    for (double& x : v) REQUIRE(static_cast<bool>(row >> x));
    CHECK(v[0] == Approx(0.01 * i).margin(1e-9));
    CHECK(std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]) ==
          Approx(1.0).epsilon(1e-9));
    CHECK(v[1] == Approx(memory.dataset.trajectory[i].position.x()).margin(1e-8));
  }
  // ground_truth.json round trip through the I/O layer, exact to the last bit.
  const ulc::io::GroundTruth gt =
      ulc::io::read_ground_truth((tmp.path / "ground_truth.json").string());
  REQUIRE(gt.lidars.size() == 2);
  CHECK(gt.lidars[0].model == "VLP-32C");
  CHECK(gt.lidars[1].T_vehicle_lidar.isApprox(spec.lidars[1].T_vehicle_lidar, 1e-14));
  REQUIRE(gt.pairs.size() == 1);
  CHECK(gt.pairs[0].base == "lidar32");
  CHECK(gt.pairs[0].target == "lidar16");
  CHECK(gt.pairs[0].T_base_target.isApprox(memory.dataset.pairs[0].T_base_target, 1e-14));
  // The file itself holds every double exactly (the reader re-orthonormalises, so check raw).
  const ulc::io::Json doc = ulc::io::read_json_file((tmp.path / "ground_truth.json").string());
  const ulc::io::Json& m = doc.at("pairs")[0].at("T_base_target");
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      CHECK(m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)].get<double>() ==
            memory.dataset.pairs[0].T_base_target.matrix()(r, c));
  REQUIRE(gt.pairs[0].time_offset_s);
  CHECK(*gt.pairs[0].time_offset_s == 0.02);
  // Writing the in-memory dataset gives the same files, byte for byte.
  TempDir again("layout_again");
  write_dataset(again.path, memory.dataset);
  auto streamed_files = snapshot(tmp.path);
  streamed_files.erase("notes.txt");
  CHECK(snapshot(again.path) == streamed_files);
  const std::string json = read_all(tmp.path / "ground_truth.json");
  CHECK(
      json.find("\"time_offset_convention\": \"t_base_clock = t_target_clock + time_offset_s\"") !=
      std::string::npos);
}

TEST_CASE("same seed, same bytes: 1 thread and 2 threads; another seed differs", "[sim][writer]") {
  auto run = [](const std::string& scenario_name, const SimulationOptions& o, int threads,
                const fs::path& dir) {
    tbb::task_arena arena(threads);
    arena.execute([&] { REQUIRE(simulate_to_directory(dir, *scenario(scenario_name), o).ok()); });
    return snapshot(dir);
  };
  // Every sensor family (spinning, Livox, decimated), and one full-resolution frame pair.
  for (const auto& [name, seconds, decimation] :
       {std::tuple{std::string("colorful"), 0.1, 16u},
        std::tuple{std::string("campus-ss"), 0.1, 8u}, std::tuple{std::string("64-32"), 0.1, 1u}}) {
    INFO(name);
    SimulationOptions o;
    o.seconds = seconds;
    o.decimation = decimation;
    o.seed = 77;
    o.grain = 256;  // many tasks, so two threads really interleave
    TempDir a(name + "_a"), b(name + "_b"), c(name + "_c");
    const auto one = run(name, o, 1, a.path);
    const auto two = run(name, o, 2, b.path);
    REQUIRE(one.size() > 3);
    CHECK(one == two);
    o.seed = 78;
    const auto other = run(name, o, 2, c.path);
    REQUIRE(other.size() == one.size());
    std::size_t same_frames = 0;
    for (const auto& [file, bytes] : one)
      if (file.find(".pcd") != std::string::npos && other.at(file) == bytes) ++same_frames;
    CHECK(same_frames == 0);
  }
}

TEST_CASE("progress hears every frame; a sink can stop the run", "[sim][writer]") {
  SimulationOptions o;
  o.seconds = 0.3;
  o.decimation = 16;
  o.keep_frames = false;
  std::vector<std::size_t> done;
  std::size_t total = 0;
  const SimulationResult r = simulate(*scenario("32-16"), o, {}, [&](std::size_t d, std::size_t t) {
    done.push_back(d);
    total = t;
  });
  REQUIRE(r.ok());
  CHECK(total == 6);
  CHECK(done == std::vector<std::size_t>{1, 2, 3, 4, 5, 6});
  CHECK(r.dataset.lidars[0].frames.empty());  // keep_frames = false
  CHECK(r.dataset.lidars[0].points > 0);
  // Frames arrive in order of their start time; stop after the third.
  std::vector<double> starts;
  const SimulationResult stopped = simulate(*scenario("32-16"), o, [&](const FrameEvent& e) {
    starts.push_back(e.timestamp);
    return starts.size() < 3;
  });
  CHECK(stopped.status == SimStatus::aborted);
  CHECK(starts.size() == 3);
  CHECK(std::is_sorted(starts.begin(), starts.end()));
}
