// bench_degenerate: on scenes that cannot pin every direction of the extrinsic, does the
// pipeline ever claim a success that is wrong?
//
//   bench_degenerate [--drives tunnel:8,highway:8,highway:4,64-32:8,64-32:8:synced] [--runs 10]
//                    [--first-run 0] [--threads 2] [--per-run] [--json]
//
// Each drive is scenario:seconds[:synced]; per drive and run (seed = run + 1) the whole
// pipeline (calibrate_pair, default options: TERRA, JEEP, HOTS; with "synced" the clocks are
// said to agree, time_offset_s = 0, as `ulc calibrate --synced-clocks`: the simulated ones do)
// calibrates the scenario's first pair and the result is compared with the truth (the paper's
// success threshold, 1 deg and 10 cm). Short drives end mostly in HOTS's time_offset_untrusted
// (10 s cannot pin a clock offset); the synced drives show whether the verdict refuses good
// answers.
// Columns: ok_right, ok_wrong (a false success: must be 0), degenerate (status degenerate,
// pipeline/observability_verdict.hpp), other (any other failure), and the free direction
// reported most often. min_share / max_share are the final problems' weakest shares over the
// runs (ulc/core/observability.hpp: below max_share = 0.01 a direction is free), which is how
// the threshold was chosen (docs/experiments/degenerate_scenes.md). fixed_cm is the largest
// translation error of a degenerate result with its free translation directions projected
// out: what the result still says about the other directions. --per-run prints every run;
// --results DIR writes each run's result file (DIR/<scenario>_<seconds>s_seed<N>.json, the
// command's format) to see why a run ended as it did.
#include <tbb/task_arena.h>
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "../tests/jeep/jeep_test_util.hpp"
#include "pipeline/calibrate.hpp"
#include "support/bench_util.hpp"
#include "ulc/core/observability.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/result_entry.hpp"

namespace {

using ulc::Isometry3d;
using ulc_bench::Cell;

struct Drive {
  std::string scenario;
  double seconds = 10.0;
  bool synced = false;
};

struct Config {
  std::vector<std::string> drives{"tunnel:8", "highway:8", "highway:4", "64-32:8",
                                  "64-32:8:synced"};
  std::size_t runs = 10;
  std::size_t first_run = 0;
  int threads = 2;
  bool per_run = false;
  std::string results_dir;  ///< empty: no result files
  ulc_bench::Options bench;
};

Drive parse_drive(const std::string& text) {
  const auto colon = text.find(':');
  Drive d;
  d.scenario = text.substr(0, colon);
  if (colon != std::string::npos) d.seconds = std::atof(text.c_str() + colon + 1);
  d.synced = text.size() > 7 && text.compare(text.size() - 7, 7, ":synced") == 0;
  if (!(d.seconds > 0.0)) {
    std::cerr << "bench_degenerate: bad drive '" << text << "' (scenario:seconds)\n";
    std::exit(2);
  }
  return d;
}

/// The translation error with its components along the free translation directions removed.
double fixed_translation_error(const ulc::PairCalibration& r, const Isometry3d& truth) {
  ulc::Vec3d e = r.T_base_target.translation() - truth.translation();
  for (const auto& d : r.unobservable) {
    const ulc::Vec3d t = d.vector.head<3>();
    if (t.squaredNorm() < 0.5) continue;  // a turn: its translation is the scene's lever
    const ulc::Vec3d u = t.normalized();
    e -= u * u.dot(e);
  }
  return e.norm();
}

struct Tally {
  std::size_t runs = 0, ok_right = 0, ok_wrong = 0, degenerate = 0, other = 0;
  double min_share = 1.0, max_share = 0.0, fixed_max_m = 0.0;
  std::map<std::string, std::size_t> directions;
  std::map<std::string, std::size_t> other_statuses;
};

std::string most_common(const std::map<std::string, std::size_t>& counts) {
  std::string best = "-";
  std::size_t n = 0;
  for (const auto& [text, count] : counts)
    if (count > n) {
      best = text;
      n = count;
    }
  return n ? best + " (" + std::to_string(n) + ")" : best;
}

/// "translation along x" from the full sentence (the part before " of the base frame").
std::string short_words(const std::string& words) {
  const auto end = words.find(" of the base frame");
  return end == std::string::npos ? words : words.substr(0, end);
}

ulc::sim::Dataset simulate(const Drive& drive, std::size_t run, tbb::task_arena& arena) {
  jeep_test::DriveSpec spec;
  spec.scenario = drive.scenario;
  spec.seconds = drive.seconds;
  spec.seed = run + 1;
  ulc::sim::Dataset d = arena.execute([&] { return jeep_test::simulate(spec); });
  if (d.lidars.size() < 2) {
    std::cerr << "bench_degenerate: cannot simulate scenario '" << drive.scenario << "'\n";
    std::exit(2);
  }
  return d;
}

void count(const ulc::PairCalibration& r, const ulc::PoseError& e, const Isometry3d& truth,
           Tally& t) {
  ++t.runs;
  if (!r.observability_problem.empty()) {
    t.min_share = std::min(t.min_share, r.weakest_share);
    t.max_share = std::max(t.max_share, r.weakest_share);
  }
  if (r.success) {
    (ulc::is_calibration_success(e) ? t.ok_right : t.ok_wrong) += 1;
  } else if (r.status == ulc::CalibrateStatus::degenerate) {
    ++t.degenerate;
    for (const auto& d : r.unobservable) ++t.directions[short_words(d.words)];
    t.fixed_max_m = std::max(t.fixed_max_m, fixed_translation_error(r, truth));
  } else {
    ++t.other;
    ++t.other_statuses[ulc::to_string(r.status)];
  }
}

/// The run's result file, as `ulc calibrate --output` writes it.
void write_result(const Config& c, const Drive& drive, std::size_t run, const ulc::sim::Dataset& d,
                  const ulc::PairCalibration& r) {
  if (c.results_dir.empty()) return;
  std::ostringstream name;
  name << c.results_dir << "/" << drive.scenario << "_" << drive.seconds << "s_seed" << run + 1
       << ".json";
  ulc::io::write_result_file(name.str(),
                             {ulc::io::to_pair_result(r, d.lidars[0].name, d.lidars[1].name)});
}

void bench(const Config& c) {
  ulc_bench::Table runs({"drive", "seed", "status", "e_rot_deg", "e_trans_cm", "fixed_cm",
                         "problem", "weakest_share", "free"});
  ulc_bench::Table table({"drive", "seeds", "ok_right", "ok_wrong", "degenerate", "other",
                          "other_statuses", "min_share", "max_share", "fixed_cm_max",
                          "free_direction"});
  tbb::task_arena arena(c.threads);
  std::size_t false_successes = 0;
  for (const std::string& text : c.drives) {
    const Drive drive = parse_drive(text);
    Tally t;
    for (std::size_t run = c.first_run; run < c.first_run + c.runs; ++run) {
      const ulc::sim::Dataset d = simulate(drive, run, arena);
      const auto& a = d.lidars[0];
      const auto& b = d.lidars[1];
      const Isometry3d truth = d.pairs.at(0).T_base_target;
      ulc::CalibrateOptions o;
      o.threads = static_cast<std::size_t>(c.threads);
      if (drive.synced) o.time_offset_s = 0.0;
      const ulc::PairCalibration r =
          ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
      const ulc::PoseError e = ulc::pose_error(truth, r.T_base_target);
      count(r, e, truth, t);
      write_result(c, drive, run, d, r);
      std::string free;
      for (const auto& dir : r.unobservable)
        free += (free.empty() ? "" : "; ") + short_words(dir.words);
      const bool degenerate = r.status == ulc::CalibrateStatus::degenerate;
      runs.add_row(
          {text, Cell::integer(static_cast<long long>(run + 1)), ulc::to_string(r.status),
           Cell::num(e.rotation_deg, 3), Cell::num(100.0 * e.translation_m, 2),
           degenerate ? Cell::num(100.0 * fixed_translation_error(r, truth), 2) : Cell("-"),
           r.observability_problem.empty() ? "-" : r.observability_problem,
           r.observability_problem.empty() ? Cell("-") : Cell::num(r.weakest_share, 5),
           free.empty() ? "-" : free});
      std::cerr << "  " << text << " seed " << run + 1 << ": " << ulc::to_string(r.status) << ", "
                << e.rotation_deg << " deg, " << 100.0 * e.translation_m << " cm, share "
                << r.weakest_share << " (" << r.observability_problem << ") " << r.reason << "\n";
    }
    false_successes += t.ok_wrong;
    std::string others;
    for (const auto& [status, n] : t.other_statuses)
      others += (others.empty() ? "" : ", ") + status + " " + std::to_string(n);
    const bool judged = t.max_share > 0.0 || t.min_share < 1.0;
    table.add_row({text, Cell::integer(static_cast<long long>(t.runs)),
                   Cell::integer(static_cast<long long>(t.ok_right)),
                   Cell::integer(static_cast<long long>(t.ok_wrong)),
                   Cell::integer(static_cast<long long>(t.degenerate)),
                   Cell::integer(static_cast<long long>(t.other)), others.empty() ? "-" : others,
                   judged ? Cell::num(t.min_share, 5) : Cell("-"),
                   judged ? Cell::num(t.max_share, 5) : Cell("-"),
                   t.degenerate ? Cell::num(100.0 * t.fixed_max_m, 2) : Cell("-"),
                   most_common(t.directions)});
  }
  if (c.per_run && !c.bench.json) {
    runs.print(std::cout);
    std::cout << "\n";
  }
  ulc_bench::emit(std::cout, table, c.bench.json, "degenerate", 1,
                  {{"runs", Cell::integer(static_cast<long long>(c.runs))},
                   {"first_run", Cell::integer(static_cast<long long>(c.first_run))},
                   {"threads", Cell::integer(c.threads)}},
                  {{"false_successes", Cell::integer(static_cast<long long>(false_successes))},
                   {"max_share", Cell::num(ulc::ObservabilityOptions{}.max_share, 4)}});
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app("The whole pipeline on degenerate and normal drives: any false success?",
               "bench_degenerate");
  ulc_bench::add_options(app, c.bench);
  app.add_option("--drives", c.drives, "scenario:seconds list")
      ->delimiter(',')
      ->type_name("S:T,...");
  app.add_option("--runs", c.runs, "runs per drive")->type_name("N")->check(CLI::PositiveNumber);
  ulc_bench::add_first_run_option(app, c.first_run);
  ulc_bench::add_threads_option(app, c.threads);
  app.add_flag("--per-run", c.per_run, "print every run's row before the summary");
  app.add_option("--results", c.results_dir, "write each run's result file into this folder")
      ->type_name("DIR")
      ->check(CLI::ExistingDirectory);
  CLI11_PARSE(app, argc, argv);
  bench(c);
  return 0;
}
