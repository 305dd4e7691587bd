// Writing a simulated dataset as the dataset folder of docs/design.md. This is I/O: failures throw
// ulc::io::IoError (file, position, reason), the I/O layer's one exception type.
//
// Layout written (and nothing else):
//   DIR/<lidar>/000000.pcd ...  binary PCD, fields x y z intensity t (float32; t = seconds
//                               since the frame timestamp), points in the LiDAR's own frame at
//                               their measurement instants, in firing order
//   DIR/<lidar>/timestamps.txt  one frame timestamp per line, seconds in that LiDAR's clock,
//                               "%.9f"
//   DIR/trajectory.txt          "t x y z qw qx qy qz" per line: T_world_vehicle at true time t
//                               (the clock of LiDARs with zero clock offset), "%.9f" for t and
//                               x y z, "%.12f" for the unit quaternion
//   DIR/ground_truth.json       lidars (model, T_vehicle_lidar), pairs (T_base_target,
//                               time_offset_s) and the offset convention, every double exactly
// Frame files that a previous, longer run left in a LiDAR folder (six-digit names beyond this
// run's frame count) are removed, so each LiDAR folder describes one run. Nothing else in DIR
// is touched: folders of LiDARs that this run does not have stay, so write each scenario into
// its own (or a fresh) folder.
//
// simulate_to_directory streams: each frame is written while the next one is ray cast (one
// TBB task), and only two frames are ever held in memory.
#pragma once

#include <tbb/task_group.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "ulc/io/file_bytes.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/pcd_write.hpp"
#include "ulc/sim/simulate.hpp"

namespace ulc::sim {

/// "000042.pcd"
inline std::string frame_file_name(std::size_t k) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu.pcd", k);
  return name;
}

namespace detail {

inline void make_directory(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw io::IoError(dir.string(), "", "cannot create directory: " + ec.message());
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  io::write_file_text(path, text);  // atomic: never half a file
}

/// Removes six-digit frame files numbered `count` and above.
inline void remove_stale_frames(const std::filesystem::path& dir, std::size_t count) {
  std::error_code ec;
  std::vector<std::filesystem::path> stale;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string stem = entry.path().stem().string();
    if (entry.path().extension() != ".pcd" || stem.size() != 6 ||
        stem.find_first_not_of("0123456789") != std::string::npos)
      continue;
    if (std::stoul(stem) >= count) stale.push_back(entry.path());
  }
  for (const auto& p : stale) {
    std::filesystem::remove(p, ec);
    if (ec) throw io::IoError(p.string(), "", "cannot remove stale frame: " + ec.message());
  }
}

inline std::string timestamps_text(const std::vector<double>& timestamps) {
  std::string text;
  char line[64];
  for (double t : timestamps) {
    std::snprintf(line, sizeof(line), "%.9f\n", t);
    text += line;
  }
  return text;
}

inline std::string trajectory_text(const std::vector<TrajectorySample>& samples) {
  std::string text;
  char line[256];
  for (const TrajectorySample& s : samples) {
    const Eigen::Quaterniond& q = s.orientation;
    std::snprintf(line, sizeof(line), "%.9f %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", s.t,
                  s.position.x(), s.position.y(), s.position.z(), q.w(), q.x(), q.y(), q.z());
    text += line;
  }
  return text;
}

inline io::GroundTruth ground_truth_of(const Dataset& d) {
  io::GroundTruth gt;
  for (const LidarRecording& l : d.lidars)
    gt.lidars.push_back({l.name, l.model, l.T_vehicle_lidar});
  for (const PairTruth& p : d.pairs)
    gt.pairs.push_back({p.base, p.target, p.T_base_target, p.time_offset_s});
  return gt;
}

}  // namespace detail

/// Writes a dataset folder frame by frame: begin(), write_frame() for every frame (any
/// order), finish().
class DatasetWriter {
 public:
  explicit DatasetWriter(std::filesystem::path dir) : dir_(std::move(dir)) {}

  const std::filesystem::path& directory() const { return dir_; }
  std::filesystem::path lidar_directory(const std::string& lidar) const { return dir_ / lidar; }

  /// Creates DIR and one folder per LiDAR of `metadata`.
  void begin(const Dataset& metadata) {
    detail::make_directory(dir_);
    for (const LidarRecording& l : metadata.lidars) detail::make_directory(dir_ / l.name);
  }

  void write_frame(const std::string& lidar, std::size_t k, const PointCloud<float>& cloud) const {
    io::write_pcd(dir_ / lidar / frame_file_name(k), cloud, io::PcdEncoding::binary);
  }

  /// Timestamps, trajectory and ground truth; removes stale frames of longer earlier runs.
  void finish(const Dataset& metadata) const {
    for (const LidarRecording& l : metadata.lidars) {
      detail::write_text(dir_ / l.name / "timestamps.txt", detail::timestamps_text(l.timestamps));
      detail::remove_stale_frames(dir_ / l.name, l.timestamps.size());
    }
    detail::write_text(dir_ / "trajectory.txt", detail::trajectory_text(metadata.trajectory));
    io::write_ground_truth((dir_ / "ground_truth.json").string(),
                           detail::ground_truth_of(metadata));
  }

 private:
  std::filesystem::path dir_;
};

/// Writes a dataset held in memory (frames in dataset.lidars[i].frames).
inline void write_dataset(const std::filesystem::path& dir, const Dataset& dataset) {
  DatasetWriter writer(dir);
  writer.begin(dataset);
  for (const LidarRecording& l : dataset.lidars)
    for (std::size_t k = 0; k < l.frames.size(); ++k) writer.write_frame(l.name, k, l.frames[k]);
  writer.finish(dataset);
}

/// Simulates and writes in one pass with bounded memory: each frame is written by a TBB task
/// while the next is ray cast. The returned Dataset holds no frames. Invalid options or
/// scenarios come back as a status (nothing written); I/O failures throw io::IoError.
inline SimulationResult simulate_to_directory(const std::filesystem::path& dir,
                                              const ScenarioSpec& spec,
                                              const SimulationOptions& options,
                                              const ProgressFn& progress = {}) {
  SimulationResult result;
  Simulator sim;
  if (!start_simulation(sim, spec, options, result)) return result;
  DatasetWriter writer(dir);
  writer.begin(result.dataset);
  const auto order = sim.schedule();
  PointCloud<float> casting, writing;
  tbb::task_group pending;
  for (std::size_t n = 0; n < order.size(); ++n) {
    const auto [lidar, k] = order[n];
    sim.render_frame(lidar, k, casting);
    result.dataset.lidars[lidar].points += casting.size();
    pending.wait();  // the previous frame is on disk (rethrows its IoError)
    std::swap(casting, writing);
    const std::string name = result.dataset.lidars[lidar].name;
    pending.run([&writer, &writing, name, k = k] { writer.write_frame(name, k, writing); });
    if (progress) progress(n + 1, order.size());
  }
  pending.wait();
  writer.finish(result.dataset);
  return result;
}

}  // namespace ulc::sim
