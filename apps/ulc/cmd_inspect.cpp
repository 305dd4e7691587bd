// `ulc inspect PATH`: what a cloud file or a LiDAR's frame folder holds. A quick check that a
// recording reads as ULC will read it (fields found, points dropped, times, extent).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli_args.hpp"
#include "commands.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/io/sequence.hpp"

namespace ulc::app {
namespace {

const char* time_source_name(io::FrameTimeSource s) {
  switch (s) {
    case io::FrameTimeSource::timestamps_file:
      return "timestamps.txt";
    case io::FrameTimeSource::point_times:
      return "per-point time field";
    case io::FrameTimeSource::file_name:
      return "file names";
    case io::FrameTimeSource::nominal_rate:
      return "none found: nominal 10 Hz";
  }
  return "?";
}

void print_frame(const io::Frame<PointCloud<double>>& f) {
  const auto& c = f.cloud;
  const auto& s = f.stats;
  std::string fields;
  for (const auto& name : s.fields) fields += (fields.empty() ? "" : " ") + name;
  std::printf("  file:        %s\n", f.path.string().c_str());
  std::printf("  format:      %s (%s)\n", s.format.c_str(), s.encoding.c_str());
  std::printf("  fields:      %s\n", fields.c_str());
  std::printf("  points:      %zu read of %zu in the file (%zu non-finite dropped)%s\n",
              s.points_read, s.points_in_file, s.points_dropped_nonfinite,
              s.height > 1 ? ", organised" : "");
  std::printf("  intensity:   %s\n",
              s.intensity_field.empty() ? "none" : s.intensity_field.c_str());
  std::printf("  time field:  %s\n", s.time_field.empty() ? "none" : s.time_field.c_str());
  if (c.empty()) return;
  Eigen::Vector3d lo = c.points[0], hi = c.points[0];
  double max_range = 0;
  for (const auto& p : c.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    max_range = std::max(max_range, p.norm());
  }
  std::printf("  extent:      x [%.2f, %.2f]  y [%.2f, %.2f]  z [%.2f, %.2f] m\n", lo.x(), hi.x(),
              lo.y(), hi.y(), lo.z(), hi.z());
  std::printf("  max range:   %.2f m\n", max_range);
  if (c.has_times()) {
    const auto [t0, t1] = std::minmax_element(c.times.begin(), c.times.end());
    std::printf("  frame time:  %.6f s; point times span [%.4f, %.4f] s after it\n", f.timestamp,
                *t0, *t1);
  } else {
    std::printf("  frame time:  %.6f s\n", f.timestamp);
  }
}

}  // namespace

int run_inspect(int argc, char** argv) {
  cli::Args args("inspect");
  args.option("path", "PATH", "a cloud file (.pcd .ply .bin) or a LiDAR's frame folder", true)
      .option("frame-index", "N", "which frame of a folder to describe (default 0)")
      .flag("help", "show this help");
  // `ulc inspect PATH` reads better than `--path PATH`: accept one positional argument.
  std::vector<char*> rewritten(argv, argv + argc);
  std::string path_flag = "--path";
  if (argc >= 2 && std::string(argv[1]).rfind("--", 0) != 0)
    rewritten.insert(rewritten.begin() + 1, path_flag.data());
  args.parse(static_cast<int>(rewritten.size()), rewritten.data(), 1);
  if (args.has("help")) {
    std::printf("%s", args.help_text("Describes a cloud file or a frame folder.").c_str());
    return kExitOk;
  }
  const io::Sequence seq(args.get("path"));
  const auto index = static_cast<std::size_t>(
      args.get_int("frame-index", 0, 0, static_cast<long long>(seq.size()) - 1));
  std::printf("%s: %zu frame%s, frame times from %s\n", args.get("path").c_str(), seq.size(),
              seq.size() == 1 ? "" : "s", time_source_name(seq.time_source()));
  if (seq.size() > 1) {
    const double span = seq.frame(seq.size() - 1).timestamp - seq.frame(0).timestamp;
    std::printf("  span:        %.3f s, mean period %.4f s\n", span,
                span / static_cast<double>(seq.size() - 1));
  }
  print_frame(seq.load_frame<PointCloud<double>>(index));
  return kExitOk;
}

}  // namespace ulc::app
