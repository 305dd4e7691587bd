// Bad input through `ulc calibrate`: each case ends with exit code 2 and one line naming the file
// and the problem, or with a result whose success is false and whose reason says why (exit code
// 1) - never a crash, a hang or an unbounded allocation. Frame times in other units than seconds
// are converted and said so; pcl_ros "sec.nsec" names are read as times and order the frames;
// Ctrl-C stops the command with exit code 130 and leaves no file behind.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "run_command.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/io/atomic_file.hpp"
#include "ulc/io/cloud_file.hpp"
#include "ulc/io/file_bytes.hpp"
#include "ulc/io/result_file.hpp"
#include "ulc_app_path.hpp"

namespace bad_input {

namespace fs = std::filesystem;
using ulc_test::CommandResult;
using ulc_test::kUlc;
using ulc_test::quote;
using ulc_test::run_command;

/// A simulated 64-32 drive of `seconds` in its own temporary folder, removed afterwards.
struct Drive {
  fs::path dir;
  Drive(const std::string& name, const std::string& seconds = "0.6")
      : dir(fs::temp_directory_path() / name) {
    fs::remove_all(dir);
    const auto run = run_command(kUlc + " simulate --quiet --scenario 64-32 --seconds " + seconds +
                                 " --seed 2 --out " + quote(dir.string()));
    INFO(run.output);
    REQUIRE(run.exit_code == 0);
  }
  ~Drive() { fs::remove_all(dir); }
  Drive(const Drive&) = delete;
  Drive& operator=(const Drive&) = delete;
  fs::path operator/(const std::string& name) const { return dir / name; }
  std::string base() const { return " --base " + quote((dir / "lidar64").string()); }
  /// `ulc calibrate` of lidar64 against `target` with `extra` options.
  CommandResult calibrate(const fs::path& target, const std::string& extra) const {
    return run_command(kUlc + " calibrate --quiet" + base() + " --target " +
                       quote(target.string()) + " " + extra);
  }
  /// A copy of lidar32's folder named `name`, to be spoiled.
  fs::path copy_of_target(const std::string& name) const {
    const fs::path copy = dir / name;
    fs::copy(dir / "lidar32", copy, fs::copy_options::recursive);
    return copy;
  }
};

std::vector<std::string> lines_of(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

void write_lines(const fs::path& file, const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  ulc::io::write_file_text(file, text);
}

std::vector<unsigned char> bytes_of(const fs::path& file) {
  return ulc::io::read_file_bytes(file);
}

void write_bytes(const fs::path& file, const std::vector<unsigned char>& bytes) {
  ulc::io::write_file_bytes(file, bytes);
}

/// Exit code 2 and exactly one line, holding every part (the file and the problem).
void check_refused(const CommandResult& run, const std::vector<std::string>& parts) {
  INFO(run.output);
  CHECK(run.exit_code == 2);
  CHECK(std::count(run.output.begin(), run.output.end(), '\n') == 1);
  for (const auto& p : parts) CHECK_THAT(run.output, Catch::Contains(p));
}

/// Exit code 1 and a result file whose only entry has success false and a reason holding `why`.
void check_failed(const CommandResult& run, const fs::path& result, const std::string& why) {
  INFO(run.output);
  CHECK(run.exit_code == 1);
  const auto r = ulc::io::read_result_file(result.string());
  REQUIRE(r.size() == 1);
  CHECK_FALSE(r[0].success);
  CHECK_THAT(r[0].reason, Catch::Contains(why));
}

/// One cloud file holding `points` (x y z float).
fs::path cloud_file(const fs::path& file, const std::vector<Eigen::Vector3f>& points) {
  ulc::io::write_cloud(file, points);
  return file;
}

int temporaries_in(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(ulc::io::kTemporaryMarker) != std::string::npos) ++n;
  return n;
}

/// The times of a LiDAR folder's timestamps.txt, in seconds.
std::vector<double> times_of(const fs::path& lidar) {
  std::vector<double> t;
  for (const auto& line : lines_of(lidar / "timestamps.txt")) t.push_back(std::stod(line));
  return t;
}

/// `ulc inspect FOLDER --frame-index k`: the line holding `label` (e.g. "frame time:").
std::string inspect_line(const fs::path& folder, std::size_t k, const std::string& label) {
  const auto run = run_command(kUlc + " inspect " + quote(folder.string()) + " --frame-index " +
                               std::to_string(k));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  const auto at = run.output.find(label);
  REQUIRE(at != std::string::npos);
  return run.output.substr(at, run.output.find('\n', at) - at);
}

std::string format(const char* pattern, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, pattern, value);
  return buf;
}

/// `ulc evaluate --json` of a result file: the first pair's success against the drive's truth.
bool evaluate_success(const Drive& d, const fs::path& result) {
  const auto run = run_command(kUlc + " evaluate --json --result " + quote(result.string()) +
                               " --ground-truth " + quote((d / "ground_truth.json").string()));
  INFO(run.output);
  const auto doc = ulc::io::parse_json(run.output);
  return run.exit_code == 0 && doc.at("pairs")[0].at("success").get<bool>();
}

/// Renames the frames of `lidar` to the names `name_of(time)` and removes its timestamps.txt.
template <typename NameOf>
void name_frames_by_time(const fs::path& lidar, NameOf name_of) {
  const auto times = times_of(lidar);
  for (std::size_t k = 0; k < times.size(); ++k) {
    char frame[32];
    std::snprintf(frame, sizeof frame, "%06zu.pcd", k);
    fs::rename(lidar / frame, lidar / (name_of(times[k]) + ".pcd"));
  }
  fs::remove(lidar / "timestamps.txt");
}

}  // namespace bad_input

using namespace bad_input;

TEST_CASE("bad input: a folder with no frames, an empty file", "[app][bad_input]") {
  const Drive d("ulc_test_bad_empty");
  fs::create_directories(d / "no_frames");
  write_lines(d / "no_frames" / "timestamps.txt", {"0.0"});
  check_refused(d.calibrate(d / "no_frames", "--stages terra"),
                {"no_frames: no frames (.pcd, .ply or .bin files) in this folder"});
  for (const char* name : {"empty.pcd", "empty.ply"}) {
    write_bytes(d / name, {});
    check_refused(d.calibrate(d / name, "--stages terra"), {name, ": empty file"});
  }
  // An empty KITTI .bin is a valid cloud of no points: nothing to calibrate, and the result says
  // so.
  write_bytes(d / "empty.bin", {});
  const fs::path result = d / "result.json";
  check_failed(d.calibrate(d / "empty.bin", "--stages terra --output " + quote(result.string())),
               result, "target cloud is empty");
}

TEST_CASE("bad input: timestamps.txt whose times go back or repeat is refused at the line",
          "[app][bad_input]") {
  const Drive d("ulc_test_bad_timestamps");
  const fs::path back = d.copy_of_target("back");
  auto times = lines_of(back / "timestamps.txt");
  REQUIRE(times.size() == 6);
  std::swap(times[2], times[3]);  // line 4 goes back
  write_lines(back / "timestamps.txt", times);
  check_refused(d.calibrate(back, "--stages terra"),
                {(back / "timestamps.txt").string(), "line 4", "goes back from", "must increase"});

  const fs::path repeat = d.copy_of_target("repeat");
  times = lines_of(repeat / "timestamps.txt");
  times[5] = times[4];  // line 6 repeats line 5
  write_lines(repeat / "timestamps.txt", times);
  check_refused(d.calibrate(repeat, "--stages terra"),
                {(repeat / "timestamps.txt").string(), "line 6", "repeats"});
}

TEST_CASE("bad input: a folder with no frame times says which rate it assumes",
          "[app][bad_input]") {
  const Drive d("ulc_test_bad_no_times");
  const fs::path bare = d.copy_of_target("bare");
  fs::remove(bare / "timestamps.txt");
  const auto run = d.calibrate(bare, "--stages terra");
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK_THAT(run.output, Catch::Contains("warning: " + bare.string() + ": no frame times") &&
                             Catch::Contains("assuming 10 Hz"));
}

TEST_CASE("bad input: frame times in milliseconds or nanoseconds are converted, and said so",
          "[app][bad_input]") {
  const Drive d("ulc_test_bad_units");
  const auto seconds = times_of(d / "lidar32");
  const std::string frame2 = "frame time:  " + format("%.6f", seconds[2]);
  struct Case {
    const char* folder;
    double per_second;
    const char* unit;
  };
  for (const Case& c : {Case{"ms", 1e3, "milliseconds"}, Case{"ns", 1e9, "nanoseconds"}}) {
    const fs::path lidar = d.copy_of_target(c.folder);
    std::vector<std::string> lines;
    for (const double t : seconds) lines.push_back(format("%.3f", t * c.per_second));
    write_lines(lidar / "timestamps.txt", lines);
    CHECK_THAT(inspect_line(lidar, 2, "frame time:"), Catch::StartsWith(frame2));
    const fs::path result = d / (std::string(c.folder) + ".json");
    const auto run =
        d.calibrate(lidar.string() + "=lidar32",
                    "--synced-clocks --stages terra,jeep --output " + quote(result.string()));
    INFO(run.output);
    CHECK(run.exit_code == 0);
    CHECK_THAT(run.output, Catch::Contains("frame times read as " + std::string(c.unit) +
                                           " and converted to seconds"));
    CHECK(evaluate_success(d, result));
  }
  // Unix times in the names: 13 digits are milliseconds, 19 nanoseconds.
  const fs::path ms_names = d.copy_of_target("ms_names");
  const auto ms_name = [](double t) { return std::round(1645000000e3 + t * 1e3); };
  name_frames_by_time(ms_names, [&](double t) { return format("%.0f", ms_name(t)); });
  CHECK_THAT(inspect_line(ms_names, 2, "frame time:"),
             Catch::StartsWith("frame time:  " + format("%.6f", ms_name(seconds[2]) / 1e3)));
  // Per-point times in milliseconds (a float field): the sweep of 100 "seconds" is converted.
  const fs::path ms_points = d.copy_of_target("ms_points");
  for (const auto& e : fs::directory_iterator(ms_points)) {
    if (e.path().extension() != ".pcd") continue;
    auto cloud = ulc::io::read_cloud<ulc::PointCloud<float>>(e.path());
    for (double& t : cloud.times) t *= 1e3;
    ulc::io::write_cloud(e.path(), cloud);
  }
  CHECK_THAT(inspect_line(ms_points, 0, "point times span ["), Catch::Contains("[0.0000, 0.1000]"));
}

TEST_CASE("bad input: pcl_ros sec.nsec names are read as times and order the frames",
          "[app][bad_input]") {
  const Drive d("ulc_test_bad_pcl_ros");
  // As ROS 2 pcl_ros pointcloud_to_pcd names them: sec "." unpadded nanosec, the clock of both
  // LiDARs started 0.0523 s into a Unix second, so some nanosecond counts have 8 digits.
  const auto pcl_ros_name = [](double t) {
    const double stamp = 1645000000.0523 + t;
    const auto sec = static_cast<long long>(stamp);
    const auto nsec = static_cast<long long>(std::llround((stamp - sec) * 1e9));
    return std::to_string(sec) + "." + std::to_string(nsec);
  };
  const auto seconds = times_of(d / "lidar32");
  for (const char* lidar : {"lidar64", "lidar32"}) name_frames_by_time(d / lidar, pcl_ros_name);
  // The first frame by time is 1645000000.52300000.pcd (8 digits), which sorts last by name.
  const std::string first = pcl_ros_name(seconds[0]) + ".pcd";
  REQUIRE(first.size() < pcl_ros_name(seconds[1]).size() + 4);
  CHECK_THAT(inspect_line(d / "lidar32", 0, "file:"), Catch::EndsWith(first));
  CHECK_THAT(inspect_line(d / "lidar32", 0, "frame time:"),
             Catch::StartsWith("frame time:  " + format("%.6f", 1645000000.0523 + seconds[0])));
  const fs::path result = d / "result.json";
  const auto run = d.calibrate(
      d / "lidar32", "--synced-clocks --stages terra,jeep --output " + quote(result.string()));
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(evaluate_success(d, result));
}

TEST_CASE("bad input: truncated and corrupted binary frames, a header claiming 2^40 points",
          "[app][bad_input]") {
  const Drive d("ulc_test_bad_binary");
  const auto frame = ulc::io::read_cloud<ulc::PointCloud<float>>(d / "lidar32" / "000000.pcd");
  auto refused = [&](const fs::path& file, const std::vector<std::string>& problem) {
    std::vector<std::string> parts{file.string()};
    parts.insert(parts.end(), problem.begin(), problem.end());
    check_refused(d.calibrate(file, "--stages terra"), parts);
  };
  auto truncated = [&](const fs::path& file, std::size_t cut) {
    auto bytes = bytes_of(file);
    bytes.resize(bytes.size() - cut);
    write_bytes(file, bytes);
    return file;
  };
  ulc::io::write_pcd(d / "binary.pcd", frame, ulc::io::PcdEncoding::binary);
  refused(truncated(d / "binary.pcd", 100), {"truncated binary data"});
  ulc::io::write_pcd(d / "compressed.pcd", frame, ulc::io::PcdEncoding::binary_compressed);
  refused(truncated(d / "compressed.pcd", 100), {"truncated compressed data"});
  ulc::io::write_ply(d / "binary.ply", frame);
  refused(truncated(d / "binary.ply", 100), {"truncated vertex data"});
  ulc::io::write_kitti_bin(d / "odd.bin", frame);
  refused(truncated(d / "odd.bin", 5), {"is not a multiple of 16"});

  // Corrupted: the compressed size of binary_compressed says more than the file holds.
  auto bytes = bytes_of(d / "lidar32" / "000001.pcd");
  ulc::io::write_pcd(d / "corrupt.pcd", frame, ulc::io::PcdEncoding::binary_compressed);
  bytes = bytes_of(d / "corrupt.pcd");
  const std::string text(bytes.begin(), bytes.end());
  const auto data_at = text.find("DATA binary_compressed\n") + 23;
  bytes[data_at + 3] = 0x7f;  // the high byte of the compressed size
  write_bytes(d / "corrupt.pcd", bytes);
  refused(d / "corrupt.pcd", {"compressed"});

  // Headers claiming 2^40 points, refused before any allocation (run under a 2 GiB address
  // space limit: an attempt to allocate for them would fail as out of memory, exit code 1).
  const std::string huge = "1099511627776";
  const std::string header =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
      "WIDTH " +
      huge + "\nHEIGHT 1\nPOINTS " + huge + "\n";
  for (const std::string kind : {"binary", "binary_compressed", "ascii"}) {
    const fs::path file = d / ("huge_" + kind + ".pcd");
    std::string text = header + "DATA " + kind + "\n";
    if (kind == "binary_compressed")  // compressed size 4, uncompressed 12 (one point), 4 bytes
      text += std::string("\x04\0\0\0\x0c\0\0\0\0\0\0\0", 12);
    else
      text += "1 2 3\n";
    ulc::io::write_file_text(file, text);
    const auto run = run_command("ulimit -v 2000000; " + kUlc + " calibrate --quiet" + d.base() +
                                 " --target " + quote(file.string()) + " --stages terra");
    check_refused(run, {file.string(), huge});
  }
  const fs::path ply = d / "huge.ply";
  write_lines(ply, {"ply", "format binary_little_endian 1.0", "element vertex " + huge,
                    "property float x", "property float y", "property float z", "end_header"});
  check_refused(d.calibrate(ply, "--stages terra"), {ply.string(), huge});
}

TEST_CASE("bad input: a damaged frame in the middle of a drive is named when the stages meet it",
          "[app][bad_input]") {
  // Frames are read when a stage needs them (ulc/core/frame_source.hpp): the odometry meets this
  // one half-way, and the command refuses the result instead of calibrating without it.
  const Drive d("ulc_test_bad_middle", "3");
  const fs::path target = d.copy_of_target("spoiled");
  const fs::path frame = target / "000015.pcd";
  auto bytes = bytes_of(frame);
  bytes.resize(bytes.size() / 2);
  write_bytes(frame, bytes);
  check_refused(d.calibrate(target, "--synced-clocks"),
                {frame.string(), "truncated binary data", "a frame could not be read"});
}

TEST_CASE("Ctrl-C stops ulc calibrate with exit code 130 and leaves no file behind",
          "[app][interrupt]") {
  const Drive d("ulc_test_interrupt", "4");
  const fs::path out = d / "out";
  fs::create_directories(out);
  // SIGINT 2 s into a calibration of every stage over 40 frames, which takes far longer.
  const auto run = run_command("timeout --preserve-status -s INT 2 " + kUlc + " calibrate --quiet" +
                               d.base() + " --target " + quote((d / "lidar32").string()) +
                               " --output " + quote((out / "result.json").string()) +
                               " --merged-cloud " + quote((out / "merged.pcd").string()) +
                               " --report " + quote((out / "report.png").string()));
  INFO(run.output);
  CHECK(run.exit_code == 130);
  CHECK_THAT(run.output, Catch::Contains("ulc calibrate: interrupted (SIGINT)"));
  CHECK(fs::is_empty(out));  // no result, no cloud, no picture, no temporary
  CHECK(temporaries_in(d.dir) == 0);
}

TEST_CASE("bad input: clouds with nothing to calibrate on fail with the reason in the result",
          "[app][bad_input]") {
  const Drive d("ulc_test_bad_clouds");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<Eigen::Vector3f> far;
  for (int i = 0; i < 5000; ++i)  // coordinates of 1e9 m, spread as a scan would be
    far.emplace_back(1e9f * std::sin(0.1f * i), 1e9f * std::cos(0.37f * i), 1e9f * std::sin(i));
  struct Case {
    const char* name;
    std::vector<Eigen::Vector3f> points;
    const char* terra_reason;  ///< TERRA's, with no guess
    const char* jeep_reason;   ///< JEEP's, from a guess
  };
  const std::vector<Case> cases = {
      {"nan", std::vector<Eigen::Vector3f>(1000, Eigen::Vector3f(nan, nan, nan)),
       "target cloud is empty", "no source points"},
      {"one_point", {Eigen::Vector3f(1, 2, 3)}, "no return beyond d1", "fewer correspondences"},
      {"origin", std::vector<Eigen::Vector3f>(5000, Eigen::Vector3f::Zero()),
       "no point in the usable range", "no source points"},
      {"far", far, "no overlap", "no source points"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    // As a single frame, with no guess: TERRA says why.
    const fs::path file = cloud_file(d / (std::string(c.name) + ".pcd"), c.points);
    const fs::path result = d / "result.json";
    check_failed(d.calibrate(file, "--stages terra --output " + quote(result.string())), result,
                 c.terra_reason);
    // As every frame of a drive, from a guess: JEEP says why, and HOTS never runs on it.
    const fs::path folder = d / c.name;
    fs::create_directories(folder);
    fs::copy_file(d / "lidar32" / "timestamps.txt", folder / "timestamps.txt");
    for (int k = 0; k < 6; ++k)
      fs::copy_file(file, folder / ("00000" + std::to_string(k) + ".pcd"));
    check_failed(d.calibrate(folder, "--stages jeep,hots --initial '0 0 0 0 0 0' --output " +
                                         quote(result.string())),
                 result, c.jeep_reason);
  }
}

TEST_CASE("bad input: every point twice still calibrates a real scene", "[app][bad_input]") {
  const Drive d("ulc_test_bad_duplicates");
  const fs::path twice = d.copy_of_target("twice");
  for (const auto& e : fs::directory_iterator(twice)) {
    if (e.path().extension() != ".pcd") continue;
    auto cloud = ulc::io::read_cloud<ulc::PointCloud<float>>(e.path());
    const auto n = cloud.points.size();
    for (std::size_t i = 0; i < n; ++i) {
      cloud.points.push_back(cloud.points[i]);
      cloud.intensities.push_back(cloud.intensities[i]);
      cloud.times.push_back(cloud.times[i]);
    }
    ulc::io::write_cloud(e.path(), cloud);
  }
  const fs::path result = d / "result.json";
  const auto run =
      d.calibrate(twice.string() + "=lidar32",
                  "--synced-clocks --stages terra,jeep --output " + quote(result.string()));
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(evaluate_success(d, result));
}

TEST_CASE("bad input: LiDARs with 60 and 3 frames calibrate, HOTS skipped and saying why",
          "[app][bad_input]") {
  const Drive d("ulc_test_bad_counts", "6");
  for (const char* short_one : {"lidar32", "lidar64"}) {
    INFO(short_one << " has 3 frames");
    const fs::path few = d / (std::string("few_") + short_one);
    fs::create_directories(few);
    auto times = lines_of(d / short_one / "timestamps.txt");
    REQUIRE(times.size() == 60);
    times.resize(3);
    write_lines(few / "timestamps.txt", times);
    for (int k = 0; k < 3; ++k) {
      const std::string frame = "00000" + std::to_string(k) + ".pcd";
      fs::copy_file(d / short_one / frame, few / frame);
    }
    const std::string base =
        short_one == std::string("lidar64") ? few.string() + "=lidar64" : (d / "lidar64").string();
    const std::string target =
        short_one == std::string("lidar32") ? few.string() + "=lidar32" : (d / "lidar32").string();
    const fs::path result = d / "result.json";
    // HOTS is skipped with 3 frames: the simulator's synchronised clocks are said so.
    const auto run =
        run_command(kUlc + " calibrate --quiet --synced-clocks --base " + quote(base) +
                    " --target " + quote(target) + " --output " + quote(result.string()));
    INFO(run.output);
    CHECK(run.exit_code == 0);
    CHECK(evaluate_success(d, result));
    const auto r = ulc::io::read_result_file(result.string());
    REQUIRE(r.size() == 1);
    CHECK(r[0].stages.at("hots").at("status").get<std::string>() == "skipped");
    CHECK_THAT(r[0].stages.at("hots").at("reason").get<std::string>(),
               Catch::Contains("only 3 frame(s)"));
  }
}

TEST_CASE("Ctrl-C stops ulc simulate with exit code 130 and no temporary left",
          "[app][interrupt]") {
  const fs::path out = fs::temp_directory_path() / "ulc_test_interrupt_simulate";
  fs::remove_all(out);
  // SIGINT 1 s into a 60 s drive, which takes far longer to write.
  const auto run =
      run_command("timeout --preserve-status -s INT 1 " + kUlc +
                  " simulate --quiet --scenario 64-32 --seconds 60 --out " + quote(out.string()));
  INFO(run.output);
  CHECK(run.exit_code == 130);
  CHECK_THAT(run.output, Catch::Contains("ulc simulate: interrupted (SIGINT)"));
  if (fs::exists(out)) CHECK(temporaries_in(out) == 0);
  CHECK_FALSE(fs::exists(out / "ground_truth.json"));  // written last, never reached
  fs::remove_all(out);
}
