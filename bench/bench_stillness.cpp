// bench_stillness: does the stillness check (pipeline/stillness.hpp) tell a parked rig from a
// moving one?
//
//   bench_stillness [--scenarios all] [--seconds 10] [--runs 5] [--first-run 0] [--threads 2]
//                   [--json]
//
// Per scenario and run (seed = run + 1) the rig is simulated twice for --seconds: driving its
// route, and parked at the spot it reaches after 5 s. The check runs on the base LiDAR's frames
// (the base of the scenario's first pair). Per scenario: how many moving drives it called still
// (must be 0: HOTS would be skipped on a drive it could use), how many it could not judge (HOTS
// then runs and judges, as before the check), the smallest move it found on a moving drive;
// how many parked recordings it called still (HOTS skipped, JEEP's answer stands), the largest
// move it found on one; and the median time of one check.
#include <tbb/task_arena.h>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "pipeline/stillness.hpp"
#include "support/bench_util.hpp"
#include "ulc/sim/simulate.hpp"

namespace {

using ulc_bench::Cell;

struct Config {
  std::vector<std::string> scenarios = ulc::sim::scenario_names();
  double seconds = 10.0;
  std::size_t runs = 5;
  std::size_t first_run = 0;
  int threads = 2;
  ulc_bench::Options bench;
};

ulc::sim::Dataset simulate(const std::string& scenario, std::uint64_t seed, double seconds,
                           bool parked) {
  ulc::sim::SimulationOptions o;
  o.seed = seed;
  o.seconds = seconds;
  if (parked) o.static_at_s = 5.0;
  const auto spec = ulc::sim::scenario(scenario);
  if (!spec) return {};
  return ulc::sim::simulate(*spec, o).dataset;
}

/// The check on the base LiDAR of the scenario's first pair, and its wall time (ms).
struct Verdict {
  ulc::StillnessReport report;
  double ms = 0.0;
};

Verdict check_base(const ulc::sim::Dataset& d) {
  const auto* base = d.find(d.pairs.front().base);
  const auto t0 = std::chrono::steady_clock::now();
  Verdict v;
  v.report = ulc::judge_stillness(base->frames, base->timestamps, ulc::StillnessOptions{});
  v.ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return v;
}

struct Tally {
  std::size_t moving = 0, moving_still = 0, moving_unjudged = 0;
  std::size_t parked = 0, parked_still = 0;
  double moving_min_travel = std::numeric_limits<double>::infinity();
  double parked_max_travel = 0.0;
  std::vector<double> ms;

  void add(const Verdict& v, bool parked_rig) {
    ms.push_back(v.ms);
    const ulc::StillnessReport& r = v.report;
    if (parked_rig) {
      ++parked;
      parked_still += r.still;
      parked_max_travel = std::max(parked_max_travel, r.max_travel_m);
      return;
    }
    ++moving;
    moving_still += r.still;
    moving_unjudged += !r.decided;
    if (r.decided) moving_min_travel = std::min(moving_min_travel, r.max_travel_m);
  }
  void add(const Tally& t) {
    moving += t.moving;
    moving_still += t.moving_still;
    moving_unjudged += t.moving_unjudged;
    parked += t.parked;
    parked_still += t.parked_still;
    moving_min_travel = std::min(moving_min_travel, t.moving_min_travel);
    parked_max_travel = std::max(parked_max_travel, t.parked_max_travel);
    ms.insert(ms.end(), t.ms.begin(), t.ms.end());
  }
  std::vector<Cell> row(const std::string& name) const {
    const auto integer = [](std::size_t n) { return Cell::integer(static_cast<long long>(n)); };
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    return {name,
            integer(moving),
            integer(moving_still),
            integer(moving_unjudged),
            std::isfinite(moving_min_travel) ? Cell::num(100.0 * moving_min_travel, 1) : Cell("-"),
            integer(parked),
            integer(parked_still),
            Cell::num(100.0 * parked_max_travel, 2),
            sorted.empty() ? Cell("-") : Cell::num(ulc_bench::median_of_sorted(sorted), 0)};
  }
};

void bench(const Config& c) {
  ulc_bench::Table table({"scenario", "moving", "moving_called_still", "moving_not_judged",
                          "moving_min_travel_cm", "parked", "parked_called_still",
                          "parked_max_travel_cm", "median_check_ms"});
  Tally all;
  tbb::task_arena arena(c.threads);
  for (const auto& scenario : c.scenarios) {
    Tally t;
    for (std::size_t run = c.first_run; run < c.first_run + c.runs; ++run)
      for (const bool parked : {false, true})
        arena.execute([&] {
          const ulc::sim::Dataset d = simulate(scenario, run + 1, c.seconds, parked);
          if (d.pairs.empty()) {
            std::cerr << "bench_stillness: cannot simulate scenario '" << scenario << "'\n";
            std::exit(2);
          }
          const Verdict v = check_base(d);
          if (!c.bench.json)
            std::cerr << "  " << scenario << " seed " << run + 1
                      << (parked ? " parked: " : " moving: ") << v.report.reason << "\n";
          t.add(v, parked);
        });
    table.add_row(t.row(scenario));
    all.add(t);
  }
  table.add_row(all.row("all"));
  ulc_bench::emit(std::cout, table, c.bench.json, "stillness", 1,
                  {{"seconds", Cell::num(c.seconds, 1)},
                   {"runs", Cell::integer(static_cast<long long>(c.runs))},
                   {"first_run", Cell::integer(static_cast<long long>(c.first_run))},
                   {"threads", Cell::integer(c.threads)}},
                  {});
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app("The stillness check on moving and parked simulated rigs", "bench_stillness");
  ulc_bench::add_options(app, c.bench);
  app.add_option("--scenarios", c.scenarios, "scenarios (default: all)")
      ->delimiter(',')
      ->type_name("A,B,...");
  app.add_option("--seconds", c.seconds, "simulated recording (default 10)")
      ->type_name("S")
      ->check(CLI::Range(0.5, 600.0));
  app.add_option("--runs", c.runs, "runs per scenario (default 5)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  ulc_bench::add_first_run_option(app, c.first_run);
  ulc_bench::add_threads_option(app, c.threads);
  CLI11_PARSE(app, argc, argv);
  bench(c);
  return 0;
}
