// bench_rig: whole simulated rigs calibrated with no initial guess (ulc::calibrate_rig), every
// target against the first LiDAR of the scenario (its base), routed through another target when
// the direct attempt fails, and the cycles base -> i -> j -> base closed with TERRA + JEEP.
//
//   bench_rig [--scenarios ring-5x16,pitched-90,side-bpearl] [--seconds 10]
//             [--stages terra,jeep,hots] [--decimation 1] [--seed 1] [--threads 2]
//             [--no-route] [--no-cycles] [--synced-clocks] [--base-odometry | --joint-odometry]
//             [--no-motion]
//             [--json]
// --synced-clocks: the pairs are told their clocks agree (the simulated rigs' do), so HOTS
// neither estimates nor checks an offset; without it, a drive too short to pin the offset down
// fails with time_offset_untrusted. --base-odometry / --joint-odometry: HOTS starts from the
// base's own odometry, run once for every target, or from both LiDARs' (default: the pipeline
// chooses, pipeline/odometry_choice.hpp). --no-motion: TERRA's motion frame off
// (map_terra_options.hpp). On stderr, per target: each stage's seconds and the TERRA hypotheses
// tried.
//
// Per target: e_rot (deg) and e_trans (cm) against the simulator's mounts, the calibration's
// status, the route, the clock offset error when HOTS ran, the cross links of the kept result
// (agreeing with the extrinsic / kept / attempted: HOTS's trust rule, include/hots/hots.hpp),
// the wall time of its calibrations (direct + routed); "bar" is the rig bar: e_rot < 0.1 deg and
// e_trans < 2 cm (and status ok). Per cycle: the closure error of T_base_i * T_i_j * T_base_j^-1
// and the i -> j status and time. One run per scenario (seed --seed): the figures are single
// measurements, not medians.
#include <tbb/task_arena.h>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "pipeline/rig.hpp"
#include "support/bench_util.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/sim/simulate.hpp"

namespace {

using ulc_bench::Cell;

struct Config {
  std::vector<std::string> scenarios{"ring-5x16", "pitched-90", "side-bpearl"};
  double seconds = 10.0;
  std::string stages = "terra,jeep,hots";
  unsigned decimation = 1;
  std::uint64_t seed = 1;
  int threads = 2;
  bool route = true;
  bool cycles = true;
  bool synced_clocks = false;  ///< --synced-clocks: no clock offset estimated (the rigs share one)
  ulc::HotsOdometry odometry = ulc::HotsOdometry::automatic;  ///< --base-/--joint-odometry
  bool motion = true;  ///< --no-motion: TERRA's motion frame off
  ulc_bench::Options bench;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Where a target's time went, on stderr: each stage's seconds summed over the TERRA hypotheses
/// tried (HOTS's odometry marked when it was the base's, run by an earlier target), and how many
/// hypotheses were tried.
void print_stage_seconds(const ulc::RigTarget& t) {
  const ulc::StageTimings& s = t.result.timing_s;
  const bool reused = t.result.hots && t.result.hots->odometry_reused;
  const std::size_t tried = t.result.terra ? t.result.terra->hypotheses.size() : 0;
  std::cerr << "  " << t.name << ": terra " << s.terra << " s, jeep " << s.jeep << " s, odometry "
            << s.odometry << " s" << (reused ? " (the base's, reused)" : "") << ", hots " << s.hots
            << " s; TERRA hypotheses tried " << tried << "\n";
}

void bench(const Config& c) {
  const ulc::ParsedStages stages = ulc::parse_stages(c.stages);
  if (!stages.ok()) {
    std::cerr << "bench_rig: --stages: " << stages.error << "\n";
    std::exit(2);
  }
  ulc_bench::Table targets({"scenario", "base", "target", "status", "route", "e_rot_deg",
                            "e_trans_cm", "dt_error_ms", "cross_links", "bar", "time_s"});
  ulc_bench::Table cycles(
      {"scenario", "cycle", "status", "closure_rot_deg", "closure_trans_cm", "time_s"});
  tbb::task_arena arena(c.threads);
  for (const auto& name : c.scenarios) {
    const auto spec = ulc::sim::scenario(name);
    if (!spec) {
      std::cerr << "bench_rig: unknown scenario '" << name << "'\n";
      std::exit(2);
    }
    ulc::sim::SimulationOptions so;
    so.seconds = c.seconds;
    so.seed = c.seed;
    so.decimation = c.decimation;
    auto t0 = std::chrono::steady_clock::now();
    const ulc::sim::SimulationResult sim =
        arena.execute([&] { return ulc::sim::simulate(*spec, so); });
    if (!sim.ok()) {
      std::cerr << "bench_rig: " << name << ": " << sim.reason << "\n";
      std::exit(1);
    }
    const ulc::sim::Dataset& d = sim.dataset;
    if (!c.bench.json)
      std::cerr << name << ": simulated " << d.lidars.size() << " LiDARs, " << c.seconds << " s in "
                << seconds_since(t0) << " s\n";

    using Frames = std::vector<ulc::PointCloud<float>>;
    std::vector<ulc::RigLidar<Frames>> lidars;
    for (const auto& l : d.lidars) lidars.push_back({l.name, &l.frames, &l.timestamps, {}});
    ulc::RigOptions o;
    o.pair.stages = stages.stages;
    if (c.synced_clocks) o.pair.time_offset_s = 0.0;
    o.pair.tuning.hots_odometry = c.odometry;
    o.pair.tuning.terra_source.maps.motion.enabled = c.motion;
    o.route = c.route;
    o.cycles = c.cycles;
    if (!c.bench.json)
      o.pair.progress = [last = std::string()](const std::string& stage, double f) mutable {
        if (stage != last && f == 0.0) std::cerr << "  " << stage << "\n";
        last = stage;
      };
    t0 = std::chrono::steady_clock::now();
    const ulc::RigCalibration rig = arena.execute([&] { return ulc::calibrate_rig(lidars, 0, o); });
    if (!c.bench.json)
      std::cerr << name << ": rig " << ulc::to_string(rig.status) << " in " << seconds_since(t0)
                << " s\n";

    const auto& base = d.lidars[rig.base];
    for (const ulc::RigTarget& t : rig.targets) {
      if (!c.bench.json && !t.direct.success)
        std::cerr << "  " << t.name << ": direct " << ulc::to_string(t.direct.status) << ": "
                  << t.direct.reason << "\n  " << t.name << ": result "
                  << ulc::to_string(t.result.status) << ": " << t.result.reason << "\n";
      if (!c.bench.json) print_stage_seconds(t);
      const auto& lidar = d.lidars[t.lidar];
      const ulc::Isometry3d truth = base.T_vehicle_lidar.inverse() * lidar.T_vehicle_lidar;
      const ulc::PoseError e = ulc::pose_error(truth, t.result.T_base_target);
      const bool hots_ran =
          t.result.hots_refined() && t.result.hots->status == hots::RefineStatus::ok;
      // t_base = t_target + offset; each LiDAR's own clock is t_true - clock_offset.
      const double true_offset = lidar.clock_offset_s - base.clock_offset_s;
      const bool bar = t.ok() && e.rotation_deg < 0.1 && e.translation_m < 0.02;
      // HOTS's trust evidence (agreeing/kept/attempted cross links), whatever its status; "-"
      // when it did not run.
      const auto& h = t.result.hots;
      const Cell links = h && h->statistics.cross_links_attempted > 0
                             ? Cell(std::to_string(h->statistics.cross_links_agreeing) + "/" +
                                    std::to_string(h->statistics.cross_links) + "/" +
                                    std::to_string(h->statistics.cross_links_attempted))
                             : Cell("-");
      targets.add_row(
          {name, rig.base_name, t.name, ulc::to_string(t.result.status),
           t.routed() ? "via " + t.via_name : std::string("direct"), Cell::num(e.rotation_deg, 4),
           Cell::num(100.0 * e.translation_m, 2),
           hots_ran ? Cell::num(1e3 * (t.result.time_offset_s - true_offset), 2) : Cell("-"), links,
           bar ? "yes" : "no", Cell::num(t.result.timing_s.total, 1)});
    }
    for (const ulc::RigCycle& cy : rig.cycles) {
      if (!c.bench.json && !cy.ok())
        std::cerr << "  cycle " << cy.name_i << "-" << cy.name_j << ": " << cy.pair.reason << "\n";
      cycles.add_row({name, rig.base_name + ">" + cy.name_i + ">" + cy.name_j,
                      ulc::to_string(cy.pair.status),
                      cy.rotation_deg ? Cell::num(*cy.rotation_deg, 4) : Cell("-"),
                      cy.translation_m ? Cell::num(100.0 * *cy.translation_m, 2) : Cell("-"),
                      Cell::num(cy.pair.timing_s.total, 1)});
    }
  }

  std::string list;
  for (const auto& s : c.scenarios) list += (list.empty() ? "" : ",") + s;
  const std::vector<std::pair<std::string, Cell>> parameters{
      {"scenarios", list},
      {"seconds", Cell::num(c.seconds, 1)},
      {"stages", c.stages},
      {"cycle_stages", "terra,jeep"},
      {"decimation", Cell::integer(c.decimation)},
      {"seed", Cell::integer(static_cast<long long>(c.seed))},
      {"threads", Cell::integer(c.threads)},
      {"route", c.route ? "on" : "off"},
      {"initial_guess", "none"}};
  const std::vector<std::pair<std::string, Cell>> notes{
      {"bar", "the rig bar: status ok and e_rot < 0.1 deg and e_trans < 2 cm"},
      {"closure", "T_base_i * T_i_j * T_base_j^-1, with T_i_j from terra,jeep on i and j"},
      {"time_s", "wall time of the target's calibrations (direct + routed) / of the cycle's"}};
  if (c.bench.json) {
    std::ostringstream a, b;
    targets.write_json(a, "bench_rig_targets", ulc_bench::machine(), 1, parameters, notes);
    cycles.write_json(b, "bench_rig_cycles", ulc_bench::machine(), 1, parameters, notes);
    std::cout << "{\"targets\": " << a.str() << ", \"cycles\": " << b.str() << "}\n";
  } else {
    targets.print(std::cout);
    std::cout << "\n";
    cycles.print(std::cout);
    ulc_bench::print_notes(std::cout, notes);
  }
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app(
      "whole simulated rigs calibrated with no initial guess (see the top of "
      "bench/bench_rig.cpp)",
      "bench_rig");
  ulc_bench::add_options(app, c.bench);
  app.add_option("--scenarios", c.scenarios, "scenarios (default ring-5x16,pitched-90,side-bpearl)")
      ->delimiter(',')
      ->type_name("A,B,...");
  app.add_option("--seconds", c.seconds, "simulated drive (default 10)")->type_name("S");
  app.add_option("--stages", c.stages, "the pairs' stages (default terra,jeep,hots)")
      ->type_name("LIST");
  app.add_option("--decimation", c.decimation, "keep every Nth point (default 1)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  app.add_option("--seed", c.seed, "simulation seed (default 1)")->type_name("N");
  ulc_bench::add_threads_option(app, c.threads);
  app.add_flag_callback(
      "--no-route", [&] { c.route = false; }, "no routes through other targets");
  app.add_flag_callback(
      "--no-cycles", [&] { c.cycles = false; }, "no cycle checks");
  app.add_flag("--synced-clocks", c.synced_clocks, "the pairs' clocks agree: no offset estimated");
  auto* base = app.add_flag_callback(
      "--base-odometry", [&] { c.odometry = ulc::HotsOdometry::base; },
      "HOTS starts from the base's own odometry, run once for every target");
  app.add_flag_callback(
         "--joint-odometry", [&] { c.odometry = ulc::HotsOdometry::joint; },
         "HOTS starts from the odometry of both LiDARs")
      ->excludes(base);
  app.add_flag_callback(
      "--no-motion", [&] { c.motion = false; }, "TERRA's motion frame off");
  CLI11_PARSE(app, argc, argv);
  bench(c);
  return 0;
}
