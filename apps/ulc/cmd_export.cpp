// `ulc export SOURCE... DIR`: LiDARs of recordings (or folders) written as the dataset folder of
// the design notes, DIR/<lidar>/000000.pcd ... with timestamps.txt, so that any tool can use the
// frames: binary PCD with x y z (intensity) and `t`, the per-point time in seconds relative to the
// frame's time, and the frame times at nanosecond precision. Frames are streamed: one in memory
// at a time.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_args.hpp"
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
  std::ofstream out(file);
  for (const double t : times) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9f\n", t);
    out << buf;
  }
  if (!out) throw io::IoError(file.string(), "", "write failed");
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
  cli::Args args("export");
  args.option("source", "SOURCE",
              "a LiDAR: FILE:TOPIC of a recording (.bag, .mcap, rosbag2 folder, .db3), a frame "
              "folder or a cloud file; =NAME names its folder",
              true, true)
      .option("out", "DIR", "the dataset folder to write (created if needed)", true)
      .flag("help", "show this help");
  add_input_options(args);
  // `ulc export SOURCE... DIR` reads better than --source/--out: accept positional arguments.
  std::vector<std::string> words;
  std::vector<char*> rewritten{argv[0]};
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) == 0) {
      rewritten.push_back(argv[i]);
      const bool takes_value = a.find('=') == std::string::npos && a != "--help";
      if (takes_value && i + 1 < argc) rewritten.push_back(argv[++i]);
    } else {
      positional.push_back(a);
    }
  }
  if (!positional.empty()) {
    words.reserve(2 * positional.size());
    for (std::size_t k = 0; k < positional.size(); ++k) {
      words.push_back(k + 1 == positional.size() ? "--out" : "--source");
      words.push_back(positional[k]);
    }
    for (auto& w : words) rewritten.push_back(w.data());
  }
  args.parse(static_cast<int>(rewritten.size()), rewritten.data(), 1);
  if (args.has("help")) {
    std::printf("%s",
                args.help_text("Writes LiDARs as the dataset folder ULC and other tools read: "
                               "DIR/<lidar>/000000.pcd ... and timestamps.txt. Usage: ulc "
                               "export drive.bag:/velodyne_points DIR")
                    .c_str());
    return kExitOk;
  }
  std::vector<LidarSpec> specs;
  for (const auto& s : args.get_all("source"))
    specs.push_back(parse_lidar_spec(s, "export", "source"));
  const auto inputs = open_lidar_inputs(specs, input_options(args, "export"), "export");
  print_input_warnings(inputs, "export");
  const fs::path out = args.get("out");
  for (const auto& input : inputs) {
    const fs::path dir = out / folder_name(input->name());
    const std::size_t n = export_lidar(*input, dir);
    std::printf("%s: %zu frames -> %s\n", input->source().c_str(), n, dir.string().c_str());
  }
  return kExitOk;
}

}  // namespace ulc::app
