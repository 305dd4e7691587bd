// bench_sim: speed of the simulator on scenario 64-32 (an HDL-64E and a VLP-32C at 10 Hz),
// 20 s of driving = 200 frames per LiDAR, ~190k rays per frame pair. Times the set-up (world,
// route, trajectory), generation alone, and generation plus writing the dataset folder, each
// inside a tbb::task_arena of 1 and of 2 threads; median over --repeats runs (default 3: one
// run is tens of seconds). Also checks that 1 and 2 threads produce identical frames (hash of
// every generated frame) and the same number of written bytes (tests/sim checks the bytes).
//
//   ./build/bench/bench_sim [--json] [--repeats N] [--seconds S] [--out DIR]
//
// --seconds changes the simulated duration (default 20); --out the scratch folder for the
// written dataset (default: a folder under the system temp directory, removed afterwards).
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "support/bench_util.hpp"
#include "ulc/sim/dataset_writer.hpp"
#include "ulc/sim/simulate.hpp"

namespace {

namespace fs = std::filesystem;
using ulc::sim::SimulationOptions;

/// FNV-1a over the frames' bytes, in production order: equal hashes, equal datasets.
struct FrameHash {
  std::uint64_t value = 1469598103934665603ULL;
  void add(const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) value = (value ^ p[i]) * 1099511628211ULL;
  }
};

struct Run {
  std::uint64_t hash = 0;
  std::size_t frames = 0;
  std::size_t points = 0;
  std::uintmax_t bytes = 0;
};

Run generate(const ulc::sim::ScenarioSpec& spec, const SimulationOptions& o) {
  Run run;
  FrameHash h;
  const auto result = ulc::sim::simulate(spec, o, [&](const ulc::sim::FrameEvent& e) {
    h.add(e.cloud.points.data(), e.cloud.points.size() * sizeof(e.cloud.points[0]));
    h.add(e.cloud.intensities.data(), e.cloud.intensities.size() * sizeof(float));
    h.add(e.cloud.times.data(), e.cloud.times.size() * sizeof(double));
    ++run.frames;
    run.points += e.cloud.size();
    return true;
  });
  if (!result.ok()) {
    std::cerr << "simulation failed: " << result.reason << "\n";
    std::exit(1);
  }
  run.hash = h.value;
  return run;
}

Run generate_and_write(const ulc::sim::ScenarioSpec& spec, const SimulationOptions& o,
                       const fs::path& dir) {
  Run run;
  const auto result = ulc::sim::simulate_to_directory(dir, spec, o);
  if (!result.ok()) {
    std::cerr << "simulation failed: " << result.reason << "\n";
    std::exit(1);
  }
  for (const auto& l : result.dataset.lidars) {
    run.frames += l.timestamps.size();
    run.points += l.points;
    for (std::size_t k = 0; k < l.timestamps.size(); ++k)
      run.bytes += fs::file_size(dir / l.name / ulc::sim::frame_file_name(k));
  }
  return run;
}

/// Median wall and median process CPU seconds (all threads) of f over `repeats` runs. CPU time
/// shows the work done even when the shared machine gives us less than the asked-for cores.
template <class F>
std::pair<double, double> wall_and_cpu(int repeats, F&& f) {
  std::vector<double> wall, cpu;
  for (int r = 0; r < repeats; ++r) {
    const std::clock_t c0 = std::clock();
    wall.push_back(ulc_bench::seconds_of(f));
    cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
  }
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  return {ulc_bench::median_of_sorted(wall), ulc_bench::median_of_sorted(cpu)};
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 20.0;
  fs::path out_dir;
  CLI::App app("simulator speed: scenario 64-32 generated and written", "bench_sim");
  ulc_bench::Options options;
  options.repeats = 3;
  ulc_bench::add_options(app, options);
  app.add_option("--seconds", seconds, "simulated drive (default 20)")->type_name("S");
  app.add_option("--out", out_dir, "write the dataset here (default: a temporary folder)")
      ->type_name("DIR");
  CLI11_PARSE(app, argc, argv);
  const bool remove_out = out_dir.empty();
  if (out_dir.empty()) out_dir = fs::temp_directory_path() / "ulc_bench_sim";

  const ulc::sim::ScenarioSpec spec = *ulc::sim::scenario("64-32");
  SimulationOptions o;
  o.seconds = seconds;
  o.seed = 1;
  o.keep_frames = false;

  ulc_bench::Table table({"step", "threads", "median_s", "cpu_s", "frames", "points_M",
                          "MB_written", "sim_s_per_wall_s"});
  std::vector<std::uint64_t> gen_hash, write_bytes;
  for (int threads : {1, 2}) {
    tbb::task_arena arena(threads);
    std::pair<double, double> setup, gen, write;
    Run g, w;
    arena.execute([&] {
      setup = wall_and_cpu(options.repeats, [&] {
        ulc::sim::Simulator sim;
        if (!sim.init(spec, o).ok()) std::exit(1);
      });
      gen = wall_and_cpu(options.repeats, [&] { g = generate(spec, o); });
      write = wall_and_cpu(options.repeats, [&] {
        fs::remove_all(out_dir);
        w = generate_and_write(spec, o, out_dir);
      });
    });
    gen_hash.push_back(g.hash);
    write_bytes.push_back(w.bytes);
    const std::string t = std::to_string(threads);
    using ulc_bench::Cell;
    table.add_row({"setup (world, route, trajectory)", t, Cell::num(setup.first, 3),
                   Cell::num(setup.second, 3)});
    table.add_row({"generate", t, Cell::num(gen.first, 2), Cell::num(gen.second, 2),
                   Cell::integer(static_cast<long long>(g.frames)), Cell::num(g.points / 1e6, 2),
                   "", Cell::num(seconds / gen.first, 2)});
    table.add_row({"generate + write", t, Cell::num(write.first, 2), Cell::num(write.second, 2),
                   Cell::integer(static_cast<long long>(w.frames)), Cell::num(w.points / 1e6, 2),
                   Cell::num(static_cast<double>(w.bytes) / 1e6, 1),
                   Cell::num(seconds / write.first, 2)});
  }
  if (remove_out) fs::remove_all(out_dir);
  const bool identical = gen_hash[0] == gen_hash[1] && write_bytes[0] == write_bytes[1];

  const ulc_bench::Machine m = ulc_bench::machine();
  const std::vector<std::pair<std::string, ulc_bench::Cell>> parameters = {
      {"scenario", "64-32"}, {"seconds", ulc_bench::Cell::num(seconds, 1)}, {"rate_hz", "10"}};
  const std::vector<std::pair<std::string, ulc_bench::Cell>> notes = {
      {"identical_1_vs_2_threads", identical ? "yes" : "NO"}};
  if (options.json) {
    table.write_json(std::cout, "bench_sim", m, options.repeats, parameters, notes);
  } else {
    std::cout << "bench_sim: scenario 64-32, " << seconds << " s at 10 Hz; " << m.cpu << ", "
              << m.threads << " threads, load " << m.load << "; median of " << options.repeats
              << "\n";
    table.print(std::cout);
    std::cout << "1 vs 2 threads identical: " << (identical ? "yes" : "NO") << "\n";
  }
  return identical ? 0 : 1;
}
