// bench_progress: how long a caller waits between two progress calls of the pipeline. The hook
// runs on the calling thread, where Python checks Ctrl-C (python/call_control.hpp), so the
// longest wait is how long Ctrl-C may go unnoticed; it is also how long a progress bar stands.
//
//   bench_progress --base DIR --target DIR [--threads 2] [--repeats 5] [--json]
//
// Both folders are read into memory first (ulc::io::Sequence); the timed call is
// calibrate_pair with every default stage and no initial guess. Per repeat: the call's wall
// time, the longest wait and the stage and fraction where that wait ended.
#include <tbb/task_arena.h>
#include <chrono>
#include <iostream>
#include <string>
#include <vector>

#include "pipeline/calibrate.hpp"
#include "support/bench_util.hpp"
#include "ulc/io/sequence.hpp"

namespace {

using ulc_bench::Cell;
using Cloud = ulc::PointCloud<float>;
using Clock = std::chrono::steady_clock;

struct Config {
  std::string base, target;
  int threads = 2;
  ulc_bench::Options bench;
};

struct Frames {
  std::vector<Cloud> clouds;
  std::vector<double> times;
};

Frames read_frames(const std::string& dir) {
  const ulc::io::Sequence sequence(dir);
  Frames out;
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    auto frame = sequence.load_frame<Cloud>(i);
    out.clouds.push_back(std::move(frame.cloud));
    out.times.push_back(frame.timestamp);
  }
  return out;
}

/// A progress hook that counts its calls and keeps the longest time between two of them (the
/// first counted from `last`, the call's start).
struct LongestWait {
  Clock::time_point last;
  double seconds = 0.0;
  std::string where;
  std::size_t calls = 0;

  void operator()(const std::string& stage, double fraction) {
    ++calls;
    const Clock::time_point now = Clock::now();
    const double wait = std::chrono::duration<double>(now - last).count();
    if (wait > seconds) {
      seconds = wait;
      where = stage + " " + Cell::num(fraction, 3).text;
    }
    last = now;
  }
};

void bench(const Config& c) {
  const Frames a = read_frames(c.base), b = read_frames(c.target);
  ulc_bench::Table table(
      {"repeat", "status", "call_s", "longest_wait_s", "wait_ends_at", "progress_calls"});
  tbb::task_arena arena(c.threads);
  for (int k = 0; k < c.bench.repeats; ++k) {
    LongestWait wait;
    ulc::CalibrateOptions o;
    o.progress = [&wait](const std::string& stage, double fraction) { wait(stage, fraction); };
    const Clock::time_point t0 = Clock::now();
    wait.last = t0;
    const ulc::PairCalibration r =
        arena.execute([&] { return ulc::calibrate_pair(a.clouds, a.times, b.clouds, b.times, o); });
    const double call_s = std::chrono::duration<double>(Clock::now() - t0).count();
    table.add_row({Cell::integer(k), ulc::to_string(r.status), Cell::num(call_s, 2),
                   Cell::num(wait.seconds, 2), wait.where,
                   Cell::integer(static_cast<long long>(wait.calls))});
  }
  ulc_bench::emit(std::cout, table, c.bench.json, "progress", 1,
                  {{"base", c.base}, {"target", c.target}, {"threads", Cell::integer(c.threads)}},
                  {});
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app("The longest wait between two progress calls of calibrate_pair", "bench_progress");
  ulc_bench::add_options(app, c.bench);
  app.add_option("--base", c.base, "the base LiDAR's frame folder")->required();
  app.add_option("--target", c.target, "the target LiDAR's frame folder")->required();
  ulc_bench::add_threads_option(app, c.threads);
  CLI11_PARSE(app, argc, argv);
  try {
    bench(c);
  } catch (const ulc::io::IoError& e) {
    std::cerr << "bench_progress: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
