// bench_bags: reading recordings into clouds. Writes a simulated 64-32 drive (an HDL-64E and a
// VLP-32C, PointCloud2 with x y z intensity and Velodyne `time`) as a ROS 1 bag, an MCAP file and
// a zstd MCAP of --gb GiB (default 1) and of --big-gb GiB (default 4; 0 skips them), then reads
// every cloud message back and decodes it into points with per-point times, as `ulc calibrate`
// does. Each read runs in a fresh process (this program with --read-child), so its peak resident
// memory (VmHWM) is the reader's own.
//
//   ./build/bench/bench_bags [--json] [--repeats N] [--gb G] [--big-gb G] [--dir DIR]
//
// Columns: MB/s of the file size per second of read + decode (median over --repeats), the raw
// read of the same file in 4 MiB blocks as the baseline of the same run (ratio = decode speed /
// raw speed), and the child's peak RSS. The files are read right after being written, so they
// come from the page cache: the figures are the reader's speed, not the disk's. The big files
// show that memory does not grow with the recording's length.
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "support/bench_util.hpp"
#include "ulc/bags/cloud_encoding.hpp"
#include "ulc/bags/cloud_topic.hpp"
#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/recording.hpp"
#include "ulc/bags/recording_writer.hpp"
#include "ulc/sim/simulate.hpp"

namespace {

namespace fs = std::filesystem;
using ulc::bags::Codec;
using ulc::bags::RecordingKind;

struct Kind {
  const char* label;
  RecordingKind kind;
  Codec codec;
  const char* extension;
};
constexpr Kind kKinds[] = {{"ROS 1 bag", RecordingKind::ros1_bag, Codec::none, ".bag"},
                           {"MCAP", RecordingKind::mcap, Codec::none, ".mcap"},
                           {"MCAP zstd", RecordingKind::mcap, Codec::zstd, ".zstd.mcap"}};

struct Message {
  std::size_t lidar;
  double time;
  ulc::io::DecodedCloud cloud;
};

/// One second of the simulated 64-32 drive, both LiDARs' frames in time order.
std::vector<Message> simulated_frames() {
  ulc::sim::SimulationOptions o;
  o.seconds = 1.0;
  std::vector<Message> out;
  const auto result =
      ulc::sim::simulate(*ulc::sim::scenario("64-32"), o, [&](const ulc::sim::FrameEvent& e) {
        Message m{e.lidar, e.timestamp, {}};
        for (std::size_t i = 0; i < e.cloud.size(); ++i) {
          m.cloud.points.push_back(e.cloud.points[i].cast<double>());
          m.cloud.intensities.push_back(e.cloud.intensities[i]);
          m.cloud.times.push_back(static_cast<float>(e.cloud.times[i]));
        }
        out.push_back(std::move(m));
        return true;
      });
  if (!result.ok()) {
    std::cerr << "simulation failed: " << result.reason << "\n";
    std::exit(1);
  }
  return out;
}

/// Writes the frames again and again (one second later each time) until `bytes` are written.
void write_recording(const fs::path& file, const Kind& kind, const std::vector<Message>& frames,
                     std::uint64_t bytes) {
  ulc::bags::RecordingWriter writer(file, {kind.kind, kind.codec, true});
  const std::size_t topics[2] = {
      writer.add_cloud_topic("/lidar64/points", ulc::bags::CloudMessageType::pointcloud2),
      writer.add_cloud_topic("/lidar32/points", ulc::bags::CloudMessageType::pointcloud2)};
  std::uint64_t raw = 0;
  const std::int64_t epoch = 1700000000LL * 1000000000LL;
  for (std::int64_t second = 0; raw < bytes; ++second)
    for (std::size_t k = 0; k < frames.size() && raw < bytes; ++k) {
      const auto stamp =
          epoch + second * 1000000000LL + static_cast<std::int64_t>(frames[k].time * 1e9);
      const auto msg =
          ulc::bags::encode_pointcloud2(frames[k].cloud, stamp, "lidar", writer.serialization(),
                                        ulc::bags::PointTimeStyle::velodyne_time);
      writer.write(topics[frames[k].lidar % 2], stamp, msg);
      raw += msg.size();
    }
  writer.close();
}

struct ReadRun {
  double seconds = 0;
  std::uint64_t points = 0;
  long peak_kib = 0;
};

/// Reads and decodes every cloud message of `file`, as the pipeline does.
ReadRun read_recording(const fs::path& file) {
  ReadRun r;
  r.seconds = ulc_bench::seconds_of([&] {
    const auto rec = ulc::bags::open_recording(file);
    std::vector<std::size_t> all;
    for (std::size_t i = 0; i < rec->topics().size(); ++i) all.push_back(i);
    auto cursor = rec->cursor(all, {});
    ulc::bags::MessageView m;
    while (cursor->next(m)) {
      const auto& topic = rec->topics()[m.topic];
      r.points +=
          ulc::bags::decode_cloud_message(*ulc::bags::cloud_message_type(topic.type), topic, m)
              .cloud.size();
    }
  });
  return r;
}

/// This process's peak resident memory (VmHWM), KiB.
long peak_rss_kib() {
  std::ifstream status("/proc/self/status");
  std::string key;
  long value = 0;
  while (status >> key)
    if (key == "VmHWM:" && status >> value) return value;
  return 0;
}

/// read_recording in a fresh process (this program, `--read-child FILE`), so that the peak
/// memory is the reader's alone, not the simulated frames this process holds.
ReadRun read_in_child(const std::string& self, const fs::path& file) {
  const std::string command = "'" + self + "' --read-child '" + file.string() + "'";
  FILE* pipe = popen(command.c_str(), "r");
  ReadRun r;
  unsigned long long points = 0;
  if (!pipe || std::fscanf(pipe, "%lf %llu %ld", &r.seconds, &points, &r.peak_kib) != 3) {
    std::cerr << "the reading child failed: " << command << "\n";
    std::exit(1);
  }
  pclose(pipe);
  r.points = points;
  return r;
}

/// Raw read of the file in 4 MiB blocks: the baseline.
double raw_read_seconds(const fs::path& file) {
  return ulc_bench::seconds_of([&] {
    const ulc::bags::FileReader in(file);
    std::vector<unsigned char> block(4 << 20);
    for (std::uint64_t at = 0; at < in.size(); at += block.size())
      in.read_into(at, block.data(), std::min<std::uint64_t>(block.size(), in.size() - at));
  });
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::strcmp(argv[1], "--read-child") == 0) {
    const ReadRun r = read_recording(argv[2]);
    std::printf("%.9f %llu %ld\n", r.seconds, static_cast<unsigned long long>(r.points),
                peak_rss_kib());
    return 0;
  }
  double gb = 1.0, big_gb = 4.0;
  fs::path dir = fs::temp_directory_path() / "ulc_bench_bags";
  CLI::App app("recordings read into clouds: MB/s and peak memory", "bench_bags");
  ulc_bench::Options options;
  ulc_bench::add_options(app, options);
  app.add_option("--gb", gb, "size of the first recording of each format (default 1)")
      ->type_name("G");
  app.add_option("--big-gb", big_gb, "size of the second, read once (default 4; 0: none)")
      ->type_name("G");
  app.add_option("--dir", dir, "where the recordings are written (default: a temporary folder)")
      ->type_name("DIR");
  CLI11_PARSE(app, argc, argv);
  fs::create_directories(dir);
  const auto frames = simulated_frames();

  ulc_bench::Table table(
      {"format", "size_GiB", "MB_per_s", "raw_MB_per_s", "ratio", "points_M", "peak_RSS_MiB"});
  for (const Kind& kind : kKinds) {
    for (const double size : {gb, big_gb}) {
      if (size <= 0) continue;
      const fs::path file =
          dir / ("drive_" + std::to_string(static_cast<int>(size * 1000)) + "MB" + kind.extension);
      write_recording(file, kind, frames, static_cast<std::uint64_t>(size * (1ull << 30)));
      const double mb = static_cast<double>(fs::file_size(file)) / 1e6;
      const int repeats = size == gb ? options.repeats : 1;
      std::vector<double> decode, raw;
      ReadRun last;
      for (int r = 0; r < repeats; ++r) {
        raw.push_back(raw_read_seconds(file));
        last = read_in_child(argv[0], file);
        decode.push_back(last.seconds);
      }
      std::sort(decode.begin(), decode.end());
      std::sort(raw.begin(), raw.end());
      const double speed = mb / ulc_bench::median_of_sorted(decode);
      const double raw_speed = mb / ulc_bench::median_of_sorted(raw);
      table.add_row(
          {kind.label,
           ulc_bench::Cell::num(static_cast<double>(fs::file_size(file)) / (1ull << 30), 2),
           ulc_bench::Cell::num(speed, 0), ulc_bench::Cell::num(raw_speed, 0),
           ulc_bench::Cell::num(speed / raw_speed, 3),
           ulc_bench::Cell::num(static_cast<double>(last.points) / 1e6, 1),
           ulc_bench::Cell::num(static_cast<double>(last.peak_kib) / 1024.0, 1)});
      fs::remove(file);
    }
  }
  ulc_bench::emit(
      std::cout, table, options.json, "bench_bags", options.repeats,
      {{"gb", ulc_bench::Cell::num(gb, 2)}, {"big_gb", ulc_bench::Cell::num(big_gb, 2)}}, {});
  return 0;
}
