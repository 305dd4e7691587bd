// `ulc inspect PATH`: what a cloud file, a LiDAR's frame folder or a recording holds. A quick
// check that data read as ULC will read it: for a recording (.bag, .mcap, rosbag2 folder, .db3)
// every topic with its type, message count, duration and rate, and which topics are clouds; for
// FILE:TOPIC, a folder or a file, the frames (fields found, per-point time and where it comes
// from, points dropped, extent).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>

#include "command_line.hpp"
#include "commands.hpp"
#include "lidar_input.hpp"
#include "ulc/bags/cloud_topic.hpp"
#include "ulc/bags/recording.hpp"
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

void print_cloud(const io::DecodedCloud& c, const io::ReadStats& s, const std::string& time_field,
                 double timestamp) {
  std::string fields;
  for (const auto& name : s.fields) fields += (fields.empty() ? "" : " ") + name;
  std::printf("  format:      %s (%s)\n", s.format.c_str(), s.encoding.c_str());
  std::printf("  fields:      %s\n", fields.c_str());
  std::printf("  points:      %zu read of %zu in the %s (%zu non-finite dropped)%s\n",
              s.points_read, s.points_in_file,
              s.format == "PointCloud2" || s.format == "CustomMsg" ? "message" : "file",
              s.points_dropped_nonfinite, s.height > 1 ? ", organised" : "");
  std::printf("  intensity:   %s\n",
              s.intensity_field.empty() ? "none" : s.intensity_field.c_str());
  std::printf("  time field:  %s\n", time_field.c_str());
  if (c.size() == 0) return;
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
    std::printf("  frame time:  %.6f s; point times span [%.4f, %.4f] s after it\n", timestamp, *t0,
                *t1);
  } else {
    std::printf("  frame time:  %.6f s\n", timestamp);
  }
}

/// Frame `index` of `count`, else UsageError.
std::size_t frame_index(long long index, std::size_t count) {
  if (index >= static_cast<long long>(count))
    throw UsageError("inspect: option '--frame-index' must be within [0, " +
                     std::to_string(count == 0 ? 0 : count - 1) + "], got " +
                     std::to_string(index));
  return static_cast<std::size_t>(index);
}

int inspect_folder(const std::string& path, long long frame_index_arg) {
  const io::Sequence seq(path);
  for (const std::string& note : seq.notes())
    std::fprintf(stderr, "ulc inspect: warning: %s\n", note.c_str());
  const std::size_t index = frame_index(frame_index_arg, seq.size());
  std::printf("%s: %zu frame%s, frame times from %s\n", path.c_str(), seq.size(),
              seq.size() == 1 ? "" : "s", time_source_name(seq.time_source()));
  if (seq.size() > 1) {
    const double span = seq.frame(seq.size() - 1).timestamp - seq.frame(0).timestamp;
    std::printf("  span:        %.3f s, mean period %.4f s\n", span,
                span / static_cast<double>(seq.size() - 1));
  }
  io::ReadStats stats;
  const io::DecodedCloud cloud = seq.load_decoded(index, &stats);
  std::printf("  file:        %s\n", seq.frame(index).path.string().c_str());
  print_cloud(cloud, stats,
              stats.time_field.empty() ? std::string("none") : "`" + stats.time_field + "`",
              seq.frame(index).timestamp);
  return kExitOk;
}

double seconds(std::int64_t ns) {
  return static_cast<double>(ns) * 1e-9;
}

void print_warnings(const bags::MessageSource& rec) {
  for (const auto& w : rec.warnings())
    std::fprintf(stderr, "ulc inspect: warning: %s\n", w.c_str());
}

int inspect_recording(const std::string& path) {
  const auto rec = bags::open_recording(path);
  print_warnings(*rec);
  std::int64_t first = std::numeric_limits<std::int64_t>::max(), last = 0;
  std::uint64_t total = 0;
  for (const auto& t : rec->topics()) {
    total += t.message_count;
    if (t.message_count == 0) continue;
    first = std::min(first, t.first_time_ns);
    last = std::max(last, t.last_time_ns);
  }
  std::printf("%s: %zu topic%s, %llu messages", path.c_str(), rec->topics().size(),
              rec->topics().size() == 1 ? "" : "s", static_cast<unsigned long long>(total));
  if (total > 0)
    std::printf(", %.3f s (%.6f to %.6f)", seconds(last - first), seconds(first), seconds(last));
  std::printf("\n");
  for (const auto& t : rec->topics()) {
    const double span = seconds(t.last_time_ns - t.first_time_ns);
    const double rate =
        t.message_count > 1 && span > 0 ? static_cast<double>(t.message_count - 1) / span : 0.0;
    std::printf("  %-32s %-36s %8llu msgs  %9.3f s  %8.2f Hz%s", t.name.c_str(), t.type.c_str(),
                static_cast<unsigned long long>(t.message_count), span, rate,
                bags::cloud_message_type(t.type) ? "  point cloud" : "");
    if (t.connections > 1) std::printf("  (%zu connections)", t.connections);
    std::printf("\n");
  }
  std::printf("point-cloud topics: %s\n", bags::describe_cloud_topics(*rec).c_str());
  return kExitOk;
}

int inspect_topic(const LidarSpec& spec, long long frame_index_arg, const InputOptions& options) {
  const auto rec = bags::open_recording(spec.path);
  print_warnings(*rec);
  const bags::CloudTopic topic(*rec, spec.topic, spec.path,
                               options.frame_time == FrameTimeChoice::receive_time
                                   ? bags::FrameTime::receive_time
                                   : bags::FrameTime::header_stamp);
  const auto& info = topic.info();
  const std::size_t index = frame_index(
      frame_index_arg, std::max<std::size_t>(1, static_cast<std::size_t>(info.message_count)));
  std::printf(
      "%s:%s: %s, %llu message%s, %s\n", spec.path.c_str(), info.name.c_str(), info.type.c_str(),
      static_cast<unsigned long long>(info.message_count), info.message_count == 1 ? "" : "s",
      options.frame_time == FrameTimeChoice::receive_time ? "frame times from the receive time"
                                                          : "frame times from header.stamp");
  if (info.message_count > 1) {
    const double span = seconds(info.last_time_ns - info.first_time_ns);
    std::printf("  span:        %.3f s received, mean period %.4f s\n", span,
                span / static_cast<double>(info.message_count - 1));
  }
  auto frames = topic.frames();
  bags::TopicFrame f;
  for (std::size_t k = 0; k <= index; ++k)
    if (!frames.next(f))
      throw UsageError("inspect: the topic has no message " + std::to_string(index));
  std::printf("  frame:       %zu, frame_id '%s'\n", index, f.message.header.frame_id.c_str());
  print_cloud(f.message.cloud, f.message.stats, bags::describe(f.message.time), f.timestamp);
  return kExitOk;
}

}  // namespace

int run_inspect(int argc, char** argv) {
  CLI::App app(
      "Describes a cloud file, a frame folder, a recording's topics, or the clouds of FILE:TOPIC.",
      "ulc inspect");
  std::string path;
  long long frame_index_arg = 0;
  // `ulc inspect PATH` reads better than `--path PATH`: both are accepted.
  app.add_option("path,--path", path,
                 "a cloud file (.pcd .ply .bin), a LiDAR's frame folder, a recording (.bag .mcap "
                 ".db3, rosbag2 folder) or FILE:TOPIC")
      ->type_name("PATH")
      ->required();
  app.add_option("--frame-index", frame_index_arg,
                 "which frame of a folder or topic to describe (default 0)")
      ->type_name("N")
      ->check(CLI::NonNegativeNumber);
  InputArgs input_args;
  add_frame_time_option(app, input_args);
  if (parse_command_line(app, "inspect", argc, argv)) return kExitOk;
  const LidarSpec spec = parse_lidar_spec(path, "inspect", "path");
  if (!spec.topic.empty())
    return inspect_topic(spec, frame_index_arg, input_options(input_args, "inspect"));
  if (bags::is_recording_path(spec.path)) return inspect_recording(spec.path);
  return inspect_folder(spec.path, frame_index_arg);
}

}  // namespace ulc::app
