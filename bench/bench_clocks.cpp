// bench_clocks: what the data cannot vouch for (pipeline/vouch.hpp). Without HOTS and without a
// known clock offset, does `--stages terra,jeep` ever claim a translation that an unestimated
// offset or an undeskewed sweep moved? And does the check still let good drives through?
//
//   bench_clocks [--cases offset-50ms,untimed-target,plain] [--seconds 15] [--runs 10]
//                [--first-run 0] [--decimation 1] [--threads 2] [--json]
//
// Cases (seed = run + 1, TERRA and JEEP with the pipeline's defaults, no offset given):
//   offset-50ms      the 64-32 rig whose VLP-32C clock runs 50 ms behind (scenario offset-50ms)
//   untimed-target   the 64-32 drive with the VLP-32C's per-point times removed (the entry
//                    synthesises them from azimuth: pipeline/point_times.hpp)
//   untimed-livox    the 64-horizon drive with the Horizon's times removed (no azimuth timing
//                    for a non-repetitive pattern: the sweep bound decides)
//   plain            the 64-32 drive as recorded (times on both, clocks synchronised)
// A false success is a success with e_rot > 1 deg or e_trans > 10 cm (the paper's threshold).
#include <tbb/task_arena.h>
#include <cstdlib>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "../tests/jeep/jeep_test_util.hpp"
#include "pipeline/calibrate.hpp"
#include "support/bench_util.hpp"
#include "ulc/core/pose_error.hpp"

namespace {

using ulc_bench::Cell;

struct Config {
  std::vector<std::string> cases{"offset-50ms", "untimed-target", "plain"};
  double seconds = 15.0;
  std::size_t runs = 10;
  std::size_t first_run = 0;
  unsigned decimation = 1;
  int threads = 2;
  ulc_bench::Options bench;
};

struct CaseSpec {
  std::string scenario;
  bool strip_target_times = false;
};

CaseSpec case_spec(const std::string& name) {
  if (name == "offset-50ms") return {"offset-50ms", false};
  if (name == "untimed-target") return {"64-32", true};
  if (name == "untimed-livox") return {"64-horizon", true};
  if (name == "plain") return {"64-32", false};
  std::cerr << "bench_clocks: unknown case '" << name << "'\n";
  std::exit(2);
}

struct Tally {
  std::size_t runs = 0, successes = 0, false_successes = 0;
};

std::string lag_text(const ulc::PairCalibration& r) {
  if (!r.clock || !r.clock->lag_checked) return "-";
  return Cell::num(r.clock->lag_s * 1e3, 1).text + " +- " +
         Cell::num(r.clock->lag_sigma_s * 1e3, 1).text;
}

void bench(const Config& c) {
  ulc_bench::Table table({"case", "seed", "status", "e_rot_deg", "e_trans_cm", "speed_mps",
                          "clock_verdict", "lag_ms", "target_times", "false_success"});
  std::map<std::string, Tally> tally;
  tbb::task_arena arena(c.threads);
  for (const std::string& name : c.cases) {
    const CaseSpec cs = case_spec(name);
    for (std::size_t run = c.first_run; run < c.first_run + c.runs; ++run) {
      jeep_test::DriveSpec spec;
      spec.scenario = cs.scenario;
      spec.seconds = c.seconds;
      spec.seed = run + 1;
      spec.decimation = c.decimation;
      ulc::sim::Dataset d = arena.execute([&] { return jeep_test::simulate(spec); });
      if (d.lidars.size() < 2) {
        std::cerr << "bench_clocks: cannot simulate scenario '" << cs.scenario << "'\n";
        std::exit(2);
      }
      auto& a = d.lidars[0];
      auto& b = d.lidars[1];
      if (cs.strip_target_times)
        for (auto& f : b.frames) f.times.clear();
      ulc::CalibrateOptions o;
      o.stages = {ulc::Stage::terra, ulc::Stage::jeep};
      const auto r = arena.execute(
          [&] { return ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o); });
      const auto e = ulc::pose_error(d.pairs.at(0).T_base_target, r.T_base_target);
      const bool false_success = r.success && !ulc::is_calibration_success(e);
      Tally& t = tally[name];
      ++t.runs;
      t.successes += r.success ? 1 : 0;
      t.false_successes += false_success ? 1 : 0;
      table.add_row({name, Cell::integer(static_cast<long long>(run + 1)), ulc::to_string(r.status),
                     Cell::num(e.rotation_deg, 3), Cell::num(100.0 * e.translation_m, 2),
                     Cell::num(r.jeep ? r.jeep->target_speed_mps : 0.0, 2),
                     r.clock ? r.clock->verdict : std::string("-"), lag_text(r),
                     ulc::to_string(r.point_times_target.source), false_success ? "YES" : "no"});
      if (!c.bench.json)
        std::cerr << "  " << name << " seed " << run + 1 << ": " << ulc::to_string(r.status) << ", "
                  << e.rotation_deg << " deg, " << 100.0 * e.translation_m << " cm; " << r.reason
                  << "\n";
    }
  }
  std::vector<std::pair<std::string, Cell>> notes;
  for (const auto& [name, t] : tally)
    notes.push_back({name, std::to_string(t.successes) + " of " + std::to_string(t.runs) +
                               " succeed, " + std::to_string(t.false_successes) +
                               " false successes"});
  ulc_bench::emit(std::cout, table, c.bench.json, "clocks", 1,
                  {{"seconds", Cell::num(c.seconds, 1)},
                   {"runs", Cell::integer(static_cast<long long>(c.runs))},
                   {"decimation", Cell::integer(c.decimation)},
                   {"threads", Cell::integer(c.threads)}},
                  notes);
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app(
      "TERRA and JEEP without a clock offset or per-point times: false successes and refusals",
      "bench_clocks");
  ulc_bench::add_options(app, c.bench);
  app.add_option("--cases", c.cases, "offset-50ms, untimed-target, untimed-livox, plain")
      ->delimiter(',')
      ->type_name("A,B,...");
  app.add_option("--seconds", c.seconds, "simulated drive (default 15)")->type_name("S");
  app.add_option("--runs", c.runs, "runs per case (default 10)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  ulc_bench::add_first_run_option(app, c.first_run);
  app.add_option("--decimation", c.decimation, "keep every d-th column (default 1)")
      ->type_name("D")
      ->check(CLI::PositiveNumber);
  ulc_bench::add_threads_option(app, c.threads);
  CLI11_PARSE(app, argc, argv);
  bench(c);
  return 0;
}
