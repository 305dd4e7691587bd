// `ulc export SOURCE... DIR`: LiDARs of recordings (or folders) written as the dataset folder of
// the design notes, DIR/<lidar>/000000.pcd ... with timestamps.txt, so that any tool can use the
// frames: binary PCD with x y z (intensity) and `t`, the per-point time in seconds relative to the
// frame's time, and the frame times at nanosecond precision. Frames are streamed: one in memory
// at a time.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "command_line.hpp"
#include "commands.hpp"
#include "lidar_input.hpp"
#include "ulc/io/pcd.hpp"

namespace ulc::app {
namespace {

namespace fs = std::filesystem;

/// A LiDAR name as a folder name: "/velodyne_points" -> "velodyne_points", "a/b" -> "a_b".
std::string folder_name(std::string name) {
  while (!name.empty() && name.front() == '/') name.erase(name.begin());
  for (char& c : name)
    if (c == '/' || c == '\\' || c == ':') c = '_';
  return name.empty() ? std::string("lidar") : name;
}

std::string frame_file(std::size_t i) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%06zu.pcd", i);
  return buf;
}

void write_timestamps(const fs::path& file, const std::vector<double>& times) {
  std::string text;
  for (const double t : times) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9f\n", t);
    text += buf;
  }
  io::write_file_text(file, text);
}

std::size_t export_lidar(const LidarInput& input, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw io::IoError(dir.string(), "", "cannot create the folder: " + ec.message());
  std::vector<double> times;
  input.visit(0, kAllFrames, [&](PointCloud<float>&& cloud, double time) {
    io::write_pcd(dir / frame_file(times.size()), cloud, io::PcdEncoding::binary);
    times.push_back(time);
    return true;
  });
  write_timestamps(dir / "timestamps.txt", times);
  return times.size();
}

}  // namespace

int run_export(int argc, char** argv) {
  CLI::App app(
      "Writes LiDARs as the dataset folder ULC and other tools read: DIR/<lidar>/000000.pcd ... "
      "and timestamps.txt. Usage: ulc export drive.bag:/velodyne_points DIR",
      "ulc export");
  std::vector<std::string> words, sources;
  std::string out_dir;
  // `ulc export SOURCE... DIR` reads better than --source/--out: both are accepted.
  app.add_option("sources", words,
                 "the LiDARs (as --source), then the dataset folder DIR unless --out names it")
      ->type_name("SOURCE");
  app.add_option("--source", sources,
                 "a LiDAR: FILE:TOPIC of a recording (.bag, .mcap, rosbag2 folder, .db3), a frame "
                 "folder or a cloud file; =NAME names its folder (repeatable)")
      ->type_name("SOURCE")
      ->allow_extra_args(false);
  auto* out_option =
      app.add_option("--out", out_dir, "the dataset folder to write (created if needed)")
          ->type_name("DIR");
  InputArgs input_args;
  add_input_options(app, input_args);
  if (parse_command_line(app, "export", argc, argv)) return kExitOk;
  if (out_option->count() == 0) {
    if (words.empty())
      throw UsageError(
          "export: the dataset folder is missing: ulc export SOURCE... DIR (or --out "
          "DIR)");
    out_dir = words.back();
    words.pop_back();
  }
  sources.insert(sources.end(), words.begin(), words.end());
  if (sources.empty())
    throw UsageError("export: no LiDAR to export: ulc export SOURCE... DIR (or --source SOURCE)");
  std::vector<LidarSpec> specs;
  for (const auto& s : sources) specs.push_back(parse_lidar_spec(s, "export", "source"));
  const auto inputs = open_lidar_inputs(specs, input_options(input_args, "export"), "export");
  print_input_warnings(inputs, "export");
  const fs::path out = out_dir;
  for (const auto& input : inputs) {
    const fs::path dir = out / folder_name(input->name());
    const std::size_t n = export_lidar(*input, dir);
    std::printf("%s: %zu frames -> %s\n", input->source().c_str(), n, dir.string().c_str());
  }
  return kExitOk;
}

}  // namespace ulc::app
