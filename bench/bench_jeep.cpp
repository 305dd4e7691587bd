// bench_jeep: JEEP, the scan-scan, GICP and NDT baselines, multi-LiDAR odometry and
// point-to-plane ICP on simulated rig drives (ulc::sim; the 20 s drives are cached under --cache,
// /tmp by default).
//
//   bench_jeep [--repeats N] [--threads N] [--json]          (d) registration speed
//   bench_jeep --accuracy   [--scenarios LIST] [--starts 50] [--frames 5] [--seed 1]
//                           [--methods jeep,scan-scan,gicp,ndt]
//   bench_jeep --separation [--scenarios LIST] [--starts 10]
//   bench_jeep --robustness [--scenarios 64-32,64-horizon] [--starts 3] [--png DIR]
//   bench_jeep --frames-sweep [--scenarios 64-32,64-horizon,64-tele] [--starts 5] [--png DIR]
//   bench_jeep --odometry   [--seconds 20] [--repeats 1]
//   common: [--seconds 20] [--seed 1] [--threads 2] [--cache DIR] [--one-way] [--json]
//   --one-way: JEEP without its two-way step (jeep/two_way.hpp), the earlier behaviour.
//
// (a) accuracy, the paper's protocol: the ground truth disturbed by 5 deg about a random axis
//     and 2 m in a random direction (seeded per start), at --starts windows spread evenly along
//     the drive; JEEP over --frames pairs from each window's first pair, scan-scan on that
//     first pair, and the GICP and NDT baselines (gicp_baseline.hpp, ndt_baseline.hpp) on that
//     same pair from the same guess, its frames prepared as scan-scan prepares them (--methods
//     picks the rows). Success: status ok (GICP, NDT: converged) and e_rot < 1 deg and
//     e_trans < 10 cm; a result reported ok but outside those is a false accept. Medians are
//     over all runs.
// separation: the acceptance rule's evidence (overlap, directional and off-ground overlap,
//     condition) for the true data and for unrelated data (b's frames from the other half of
//     the drive, relabelled in time).
// (b) robustness: success and median errors over a 6x6 grid of initial rotation (0..12.5 deg) x
//     translation (0..5 m) disturbance (with --png, three maps per scenario: success in %,
//     e_rot in millidegrees, e_trans in millimetres; the paper's figure); --frames-sweep: success
//     and errors for K = 2..12 at 5 deg, 2 m.
// (c) odometry: multi-LiDAR odometry over the drive with the true extrinsic: relative
//     translation drift against the simulator's trajectory, and frame pairs per second on 1 and
//     --threads threads.
// (d) registration speed: point-to-plane ICP of a VLP-32C frame onto an HDL-64E frame (same
//     gate, kernel and iteration cap for every variant), the two targets (kd-tree PlaneCloud,
//     voxel LocalMap) and their query cost. PCL / Open3D peers only if their Debian packages
//     are installed (they are not on the reference machine: the bench never links them).
#include <tbb/task_arena.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../tests/jeep/jeep_test_util.hpp"
#include "gicp_baseline.hpp"
#include "jeep/jeep.hpp"
#include "jeep/scan_scan.hpp"
#include "ndt_baseline.hpp"
#include "odometry/run_odometry.hpp"
#include "support/bench_util.hpp"
#include "support/heatmap_png.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/registration_target.hpp"

namespace {

using jeep_test::DriveSpec;
using ulc::Isometry3d;
using ulc_bench::Cell;
using Frames = std::vector<ulc::PointCloud<float>>;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct Config {
  std::string mode = "registration";
  std::vector<std::string> scenarios;
  std::size_t starts = 0;  ///< 0: the mode's default
  std::size_t frames = 5;
  double seconds = 20.0;
  std::uint64_t seed = 1;
  int threads = 2;
  std::string cache = "/tmp/ulc_jeep_cache";
  std::string png_dir;   ///< --png DIR: robustness and frames-sweep heat maps as PNG
  bool one_way = false;  ///< --one-way: JEEP without the two-way step
  std::vector<std::string> methods = {"jeep", "scan-scan", "gicp", "ndt"};  ///< --accuracy's rows
  ulc_bench::Options bench;
};

/// JEEP's options for K frame pairs, as the command line asks.
jeep::JeepOptions jeep_options(const Config& c, std::size_t frames) {
  jeep::JeepOptions o;
  o.frames = frames;
  o.two_way = !c.one_way;
  return o;
}

template <class F>
auto in_arena(int threads, F&& f) {
  tbb::task_arena arena(threads);
  return arena.execute(std::forward<F>(f));
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// A window of a LiDAR's frames without copying them (JEEP takes any random-access container).
struct FrameWindow {
  const Frames* frames = nullptr;
  std::vector<std::size_t> index;
  std::size_t size() const { return index.size(); }
  const ulc::PointCloud<float>& operator[](std::size_t i) const { return (*frames)[index[i]]; }
};

struct Drive {
  ulc::sim::Dataset data;
  std::vector<odometry::FramePair> pairs;  ///< every pair of the drive
  Isometry3d truth = Isometry3d::Identity();
  const ulc::sim::LidarRecording& a() const { return data.lidars[0]; }
  const ulc::sim::LidarRecording& b() const { return data.lidars[1]; }
};

Drive load_drive(const std::string& scenario, const Config& c) {
  DriveSpec spec;
  spec.scenario = scenario;
  spec.seconds = c.seconds;
  spec.seed = c.seed;
  std::cerr << "bench_jeep: loading " << scenario << " (" << c.seconds << " s, simulated once and "
            << "cached in " << c.cache << ")\n";
  Drive d;
  d.data = jeep_test::cached(spec, c.cache);
  d.truth = d.data.pairs.at(0).T_base_target;
  const double period = odometry::frame_period(d.a().timestamps);
  d.pairs = odometry::pair_frames(d.a().timestamps, d.b().timestamps, 0.0, 0.5 * period);
  return d;
}

/// Window of K pairs from pair `first`: frames and timestamps of both LiDARs.
struct Window {
  FrameWindow a, b;
  std::vector<double> ta, tb;
};

Window window(const Drive& d, std::size_t first, std::size_t K, std::size_t b_first = SIZE_MAX) {
  Window w;
  w.a.frames = &d.a().frames;
  w.b.frames = &d.b().frames;
  for (std::size_t k = 0; k < K && first + k < d.pairs.size(); ++k) {
    const auto& p = d.pairs[first + k];
    w.a.index.push_back(p.a);
    w.ta.push_back(d.a().timestamps[p.a]);
    if (b_first == SIZE_MAX) {
      w.b.index.push_back(p.b);
      w.tb.push_back(d.b().timestamps[p.b]);
    } else {  // unrelated: b from elsewhere, stamped to pair with a
      w.b.index.push_back(d.pairs[b_first + k].b);
      w.tb.push_back(d.b().timestamps[p.b]);
    }
  }
  return w;
}

std::vector<std::size_t> start_pairs(const Drive& d, std::size_t starts, std::size_t K) {
  std::vector<std::size_t> out;
  if (d.pairs.size() < K) return out;
  const std::size_t last = d.pairs.size() - K;
  for (std::size_t i = 0; i < starts; ++i) out.push_back(starts == 1 ? 0 : i * last / (starts - 1));
  return out;
}

Isometry3d disturbance_for(const Drive& d, const Config& c, std::size_t start, double deg,
                           double metres, std::uint64_t salt = 0) {
  std::mt19937_64 rng(c.seed * 1000003ULL + start * 7919ULL + salt);
  return jeep_test::disturbed(d.truth, rng, deg * kDeg, metres);
}

struct Outcome {
  bool ok = false;
  std::string status;
  ulc::PoseError error;
  double seconds = 0.0;
  double overlap = 0.0;
  double directional_overlap = 0.0;
  double off_ground_overlap = 0.0;
  double condition = 0.0;
  int rounds = 0;
};

bool success(const Outcome& o) {
  return o.ok && ulc::is_calibration_success(o.error);
}

struct Summary {
  std::size_t runs = 0, successes = 0, accepted = 0, false_accepts = 0, within = 0;
  std::vector<double> rot, trans, time, rounds;
  void add(const Outcome& o) {
    ++runs;
    successes += success(o) ? 1 : 0;
    accepted += o.ok ? 1 : 0;
    false_accepts += o.ok && !ulc::is_calibration_success(o.error) ? 1 : 0;
    within += ulc::is_calibration_success(o.error) ? 1 : 0;
    rot.push_back(o.error.rotation_deg);
    trans.push_back(o.error.translation_m);
    time.push_back(o.seconds);
    rounds.push_back(o.rounds);
  }
  double pct(std::size_t n) const { return runs ? 100.0 * n / runs : 0.0; }
};

Outcome run_jeep(const Window& w, const Isometry3d& initial, const Isometry3d& truth,
                 const jeep::JeepOptions& o, int threads) {
  Outcome out;
  const auto t0 = std::chrono::steady_clock::now();
  const auto r =
      in_arena(threads, [&] { return jeep::run_jeep(w.a, w.ta, w.b, w.tb, initial, o); });
  out.seconds = seconds_since(t0);
  out.ok = r.ok();
  out.status = jeep::to_string(r.status);
  out.error = ulc::pose_error(truth, r.extrinsic);
  out.overlap = r.acceptance.overlap;
  out.directional_overlap = r.acceptance.directional_overlap;
  out.off_ground_overlap = r.acceptance.off_ground_overlap;
  out.condition = r.acceptance.condition;
  out.rounds = r.rounds;
  return out;
}

Outcome run_scan_scan(const Drive& d, std::size_t pair, const Isometry3d& initial, int threads) {
  Outcome out;
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = in_arena(threads, [&] {
    return jeep::scan_to_scan(d.a().frames[d.pairs[pair].a], d.b().frames[d.pairs[pair].b],
                              initial);
  });
  out.seconds = seconds_since(t0);
  out.ok = r.ok();
  out.status = jeep::to_string(r.status);
  out.error = ulc::pose_error(d.truth, r.extrinsic);
  out.overlap = r.acceptance.overlap;
  out.directional_overlap = r.acceptance.directional_overlap;
  out.off_ground_overlap = r.acceptance.off_ground_overlap;
  out.condition = r.acceptance.condition;
  return out;
}

/// A frame as scan-scan prepares it (jeep/scan_scan.hpp): odometry::prepare_scan with
/// jeep::ScanScanOptions' scan options (2-100 m, 0.25 m voxel centroids, no deskew), its dense
/// points (the ones scan-scan registers), in double for the refinement baselines.
std::vector<ulc::Vec3d> scan_scan_points(const ulc::PointCloud<float>& frame) {
  const jeep::ScanScanOptions o;
  const auto scan = odometry::prepare_scan<float>(frame, ulc::Vec6d::Zero(), 0.0, o.scan);
  std::vector<ulc::Vec3d> out;
  out.reserve(scan.dense.size());
  for (const auto& p : scan.dense) out.push_back(p.cast<double>());
  return out;
}

/// A refinement baseline on the scan-scan pair from the same guess: target = the base LiDAR's
/// frame (a), source = the target LiDAR's (b), so its pose is C = T_base_target; `refine(source,
/// target)` returns the baseline's result. Frames prepared by scan_scan_points; the time
/// includes that. ok = converged.
template <class Refine>
Outcome run_baseline(const Drive& d, std::size_t pair, int threads, Refine&& refine) {
  Outcome out;
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = in_arena(threads, [&] {
    const auto target = scan_scan_points(d.a().frames[d.pairs[pair].a]);
    const auto source = scan_scan_points(d.b().frames[d.pairs[pair].b]);
    return refine(source, target);
  });
  out.seconds = seconds_since(t0);
  out.ok = r.converged;
  out.status = r.converged ? "ok" : "not_converged";
  out.error = ulc::pose_error(d.truth, r.pose);
  out.rounds = r.iterations;
  return out;
}

Outcome run_gicp(const Drive& d, std::size_t pair, const Isometry3d& initial, int threads) {
  return run_baseline(d, pair, threads, [&](const auto& source, const auto& target) {
    return gicp_baseline::gicp(source, target, initial);
  });
}

Outcome run_ndt(const Drive& d, std::size_t pair, const Isometry3d& initial, int threads) {
  return run_baseline(d, pair, threads, [&](const auto& source, const auto& target) {
    return ndt_baseline::ndt(source, target, initial);
  });
}

void emit(const ulc_bench::Table& table, const std::string& name, const Config& c,
          const std::vector<std::pair<std::string, Cell>>& parameters,
          const std::vector<std::pair<std::string, Cell>>& notes = {}) {
  ulc_bench::emit(std::cout, table, c.bench.json, name, c.bench.repeats, parameters, notes);
}

std::string scenario_list(const Config& c) {
  std::string s;
  for (const auto& x : c.scenarios) s += (s.empty() ? "" : ",") + x;
  return s;
}

// ---------------------------------------------------------------------------------------------
// (a) accuracy

/// One --accuracy run of `method` from start pair s: JEEP over the window, the others on its
/// first pair.
Outcome run_method(const std::string& method, const Drive& d, std::size_t s,
                   const Isometry3d& initial, const jeep::JeepOptions& o, const Config& c) {
  if (method == "jeep") return run_jeep(window(d, s, c.frames), initial, d.truth, o, c.threads);
  if (method == "scan-scan") return run_scan_scan(d, s, initial, c.threads);
  if (method == "gicp") return run_gicp(d, s, initial, c.threads);
  return run_ndt(d, s, initial, c.threads);
}

/// One run's line on stderr (JEEP's with its acceptance evidence).
void log_run(const std::string& scenario, std::size_t s, const std::string& method,
             const Outcome& r) {
  std::cerr << "  " << scenario << " start " << s << ": " << method << " " << r.status << " after "
            << r.rounds << (method == "jeep" ? " rounds" : " iterations") << ", e_rot "
            << r.error.rotation_deg << " e_trans " << r.error.translation_m;
  if (method == "jeep") std::cerr << ", overlap " << r.overlap << ", condition " << r.condition;
  std::cerr << " (" << r.seconds << " s)\n";
}

void accuracy(Config c) {
  if (c.scenarios.empty())
    c.scenarios = {"64-32", "32-16", "horizon-tele", "64-horizon", "32-avia", "64-tele"};
  if (!c.starts) c.starts = 50;
  ulc_bench::Table table({"scenario", "method", "runs", "success_pct", "accepted_pct",
                          "false_accepts", "median_e_rot_deg", "median_e_trans_cm", "p90_e_rot_deg",
                          "p90_e_trans_cm", "median_rounds", "median_time_s"});
  const jeep::JeepOptions o = jeep_options(c, c.frames);
  for (const auto& scenario : c.scenarios) {
    const Drive d = load_drive(scenario, c);
    // One summary per method, in --methods order: the table's rows.
    std::vector<std::pair<std::string, Summary>> summaries;
    for (const auto& method : c.methods) summaries.emplace_back(method, Summary{});
    for (std::size_t s : start_pairs(d, c.starts, c.frames)) {
      const Isometry3d initial = disturbance_for(d, c, s, 5.0, 2.0);
      for (auto& [method, summary] : summaries) {
        const Outcome r = run_method(method, d, s, initial, o, c);
        summary.add(r);
        if (!c.bench.json && method != "scan-scan") log_run(scenario, s, method, r);
      }
    }
    for (const auto& [method, sum] : summaries) {
      auto p90 = [](std::vector<double> v) {
        if (v.empty()) return 0.0;
        std::sort(v.begin(), v.end());
        return v[static_cast<std::size_t>(0.9 * (v.size() - 1))];
      };
      table.add_row({scenario, method, Cell::integer(static_cast<long long>(sum.runs)),
                     Cell::num(sum.pct(sum.successes), 1), Cell::num(sum.pct(sum.accepted), 1),
                     Cell::integer(static_cast<long long>(sum.false_accepts)),
                     Cell::num(jeep_test::median(sum.rot), 4),
                     Cell::num(100 * jeep_test::median(sum.trans), 2), Cell::num(p90(sum.rot), 4),
                     Cell::num(100 * p90(sum.trans), 2),
                     Cell::num(method == "jeep" ? jeep_test::median(sum.rounds) : 0.0, 1),
                     Cell::num(jeep_test::median(sum.time), 3)});
    }
  }
  emit(table, "bench_jeep_accuracy", c,
       {{"scenarios", scenario_list(c)},
        {"starts", Cell::integer(static_cast<long long>(c.starts))},
        {"frames", Cell::integer(static_cast<long long>(c.frames))},
        {"seconds", Cell::num(c.seconds, 1)},
        {"seed", Cell::integer(static_cast<long long>(c.seed))},
        {"threads", Cell::integer(c.threads)},
        {"disturbance", "5 deg about a random axis, 2 m in a random direction"}},
       {{"success", "status ok and e_rot < 1 deg and e_trans < 10 cm"},
        {"gicp",
         "plane-to-plane Generalized-ICP (Segal et al. 2009, bench/gicp_baseline.hpp) on the "
         "scan-scan pair from the same guess, frames prepared as scan-scan's (2-100 m, 0.25 m "
         "voxels), gates 4/1.5/0.6/0.3 m; ok = converged"},
        {"ndt",
         "point-to-distribution NDT (Magnusson 2009, bench/ndt_baseline.hpp) on the scan-scan "
         "pair from the same guess, frames prepared as scan-scan's, cells 4/2/1 m, each point "
         "scored against its cell and the six face neighbours; ok = converged"},
        {"medians", "over all runs, failures included"}});
}

// ---------------------------------------------------------------------------------------------
// separation of the acceptance rule

void separation(Config c) {
  if (c.scenarios.empty())
    c.scenarios = {"64-32", "32-16", "horizon-tele", "64-horizon", "32-avia", "64-tele"};
  if (!c.starts) c.starts = 10;
  ulc_bench::Table table({"scenario", "data", "runs", "settled", "accepted_pct", "overlap_median",
                          "dir_overlap_min", "dir_overlap_max", "off_ground_min",
                          "off_ground_median", "off_ground_max", "condition_min"});
  const jeep::JeepOptions o = jeep_options(c, c.frames);
  for (const auto& scenario : c.scenarios) {
    const Drive d = load_drive(scenario, c);
    const std::size_t half = d.pairs.size() / 2;
    for (int unrelated = 0; unrelated < 2; ++unrelated) {
      std::vector<double> overlap, directional, off_ground, condition;
      std::size_t accepted = 0, runs = 0;
      for (std::size_t s : start_pairs(d, c.starts, c.frames)) {
        // Unrelated: b's frames from half a drive away (another street), a's timestamps.
        std::size_t b_first = SIZE_MAX;
        if (unrelated) b_first = (s + half) % (d.pairs.size() - c.frames);
        const Isometry3d initial = disturbance_for(d, c, s, 5.0, 2.0);
        const Outcome r = run_jeep(window(d, s, c.frames, b_first), initial, d.truth, o, c.threads);
        ++runs;
        accepted += r.ok ? 1 : 0;
        // The rule judges settled runs only; a true run that settled away from the truth is
        // not evidence of what the truth looks like.
        const bool settled = r.status == "ok" || r.status == "rejected";
        if (!settled || (!unrelated && !ulc::is_calibration_success(r.error))) continue;
        overlap.push_back(r.overlap);
        directional.push_back(r.directional_overlap);
        off_ground.push_back(r.off_ground_overlap);
        condition.push_back(r.condition);
      }
      auto mn = [](const std::vector<double>& v) {
        return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end());
      };
      auto mx = [](const std::vector<double>& v) {
        return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
      };
      table.add_row({scenario, unrelated ? "unrelated" : "true",
                     Cell::integer(static_cast<long long>(runs)),
                     Cell::integer(static_cast<long long>(overlap.size())),
                     Cell::num(runs ? 100.0 * accepted / runs : 0.0, 1),
                     Cell::num(jeep_test::median(overlap), 3), Cell::num(mn(directional), 3),
                     Cell::num(mx(directional), 3), Cell::num(mn(off_ground), 3),
                     Cell::num(jeep_test::median(off_ground), 3), Cell::num(mx(off_ground), 3),
                     Cell::num(mn(condition), 4)});
    }
  }
  emit(
      table, "bench_jeep_separation", c,
      {{"scenarios", scenario_list(c)},
       {"starts", Cell::integer(static_cast<long long>(c.starts))},
       {"frames", Cell::integer(static_cast<long long>(c.frames))}},
      {{"settled",
        "runs the rule judged (status ok or rejected); true data: and within the "
        "success bounds; the statistics are over these"},
       {"overlap", "agreeing / near points of the smaller map (acceptance.hpp)"},
       {"dir_overlap", "agreeing share of the near points' information in the weakest direction"},
       {"off_ground", "the same over the directions the dominant plane (the ground) leaves free"},
       {"rule",
        "accept iff off_ground >= " +
            std::to_string(jeep::AcceptanceOptions{}.min_off_ground_overlap) + ", dir_overlap >= " +
            std::to_string(jeep::AcceptanceOptions{}.min_directional_overlap) +
            " and condition >= " + std::to_string(jeep::AcceptanceOptions{}.min_condition)}});
}

// ---------------------------------------------------------------------------------------------
// (b) robustness

std::string format_fixed(double v, int decimals) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(decimals);
  out << v;
  return out.str();
}

/// With --png DIR, the heat map goes to DIR/name (a failure is reported, not fatal).
void write_png(const Config& c, const std::string& name, const ulc_bench::Heatmap& map) {
  if (c.png_dir.empty()) return;
  const std::string path = c.png_dir + "/" + name;
  if (ulc_bench::write_heatmap_png(path, map))
    std::cerr << "bench_jeep: wrote " << path << "\n";
  else
    std::cerr << "bench_jeep: could not write " << path << "\n";
}

void robustness(Config c) {
  if (c.scenarios.empty()) c.scenarios = {"64-32", "64-horizon"};
  if (!c.starts) c.starts = 3;
  ulc_bench::Table table({"scenario", "rot_deg", "trans_m", "runs", "success_pct",
                          "median_e_rot_deg", "median_e_trans_cm"});
  const jeep::JeepOptions o = jeep_options(c, c.frames);
  for (const auto& scenario : c.scenarios) {
    const Drive d = load_drive(scenario, c);
    // Rows: rotation disturbance, columns: translation disturbance. Success in %; the median
    // errors in millidegrees and millimetres, green at 0 and red at kRedMdeg / kRedMm.
    constexpr double kRedMdeg = 50.0, kRedMm = 10.0;
    ulc_bench::Heatmap success, rot, trans;
    rot.red_at = kRedMdeg, rot.green_at = 0.0;
    trans.red_at = kRedMm, trans.green_at = 0.0;
    for (int ri = 0; ri < 6; ++ri) {
      for (auto* m : {&success, &rot, &trans}) {
        m->row_labels.push_back(format_fixed(2.5 * ri, 1));
        m->column_labels.push_back(format_fixed(1.0 * ri, 0));
        m->values.emplace_back();
      }
      for (int ti = 0; ti < 6; ++ti) {
        const double deg = 2.5 * ri, metres = 1.0 * ti;
        Summary sum;
        for (std::size_t s : start_pairs(d, c.starts, c.frames))
          sum.add(run_jeep(window(d, s, c.frames), disturbance_for(d, c, s, deg, metres, 17),
                           d.truth, o, c.threads));
        success.values.back().push_back(sum.pct(sum.successes));
        rot.values.back().push_back(1000 * jeep_test::median(sum.rot));
        trans.values.back().push_back(1000 * jeep_test::median(sum.trans));
        table.add_row({scenario, Cell::num(deg, 1), Cell::num(metres, 1),
                       Cell::integer(static_cast<long long>(sum.runs)),
                       Cell::num(sum.pct(sum.successes), 1),
                       Cell::num(jeep_test::median(sum.rot), 4),
                       Cell::num(100 * jeep_test::median(sum.trans), 2)});
        if (!c.bench.json)
          std::cerr << "  " << scenario << " " << deg << " deg " << metres
                    << " m: " << sum.pct(sum.successes) << "%\n";
      }
    }
    write_png(c, "jeep_robustness_" + scenario + ".png", success);
    write_png(c, "jeep_robustness_" + scenario + "_e_rot_mdeg.png", rot);
    write_png(c, "jeep_robustness_" + scenario + "_e_trans_mm.png", trans);
  }
  emit(table, "bench_jeep_robustness", c,
       {{"scenarios", scenario_list(c)},
        {"starts", Cell::integer(static_cast<long long>(c.starts))},
        {"frames", Cell::integer(static_cast<long long>(c.frames))}});
}

void frames_sweep(Config c) {
  if (c.scenarios.empty()) c.scenarios = {"64-32", "64-horizon", "64-tele"};
  if (!c.starts) c.starts = 5;
  ulc_bench::Table table({"scenario", "frames", "runs", "success_pct", "median_e_rot_deg",
                          "median_e_trans_cm", "median_time_s"});
  ulc_bench::Heatmap map;  // rows: scenarios, columns: K
  for (std::size_t K = 2; K <= 12; ++K) map.column_labels.push_back(std::to_string(K));
  for (const auto& scenario : c.scenarios) {
    const Drive d = load_drive(scenario, c);
    map.row_labels.push_back(std::to_string(map.row_labels.size() + 1));
    map.values.emplace_back();
    for (std::size_t K = 2; K <= 12; ++K) {
      const jeep::JeepOptions o = jeep_options(c, K);
      Summary sum;
      for (std::size_t s : start_pairs(d, c.starts, 12))
        sum.add(
            run_jeep(window(d, s, K), disturbance_for(d, c, s, 5.0, 2.0), d.truth, o, c.threads));
      map.values.back().push_back(sum.pct(sum.successes));
      table.add_row({scenario, Cell::integer(static_cast<long long>(K)),
                     Cell::integer(static_cast<long long>(sum.runs)),
                     Cell::num(sum.pct(sum.successes), 1), Cell::num(jeep_test::median(sum.rot), 4),
                     Cell::num(100 * jeep_test::median(sum.trans), 2),
                     Cell::num(jeep_test::median(sum.time), 3)});
      if (!c.bench.json)
        std::cerr << "  " << scenario << " K " << K << ": " << sum.pct(sum.successes) << "%\n";
    }
  }
  write_png(c, "jeep_frames.png", map);
  emit(table, "bench_jeep_frames", c,
       {{"scenarios", scenario_list(c)},
        {"starts", Cell::integer(static_cast<long long>(c.starts))},
        {"disturbance", "5 deg, 2 m"}});
}

// ---------------------------------------------------------------------------------------------
// (c) odometry

void odometry_bench(Config c) {
  if (c.scenarios.empty()) c.scenarios = {"64-32"};
  ulc_bench::Table table({"scenario", "mode", "threads", "pairs", "path_m", "end_drift_pct",
                          "segment_drift_pct", "rotation_drift_deg_per_100m", "pairs_per_s"});
  for (const auto& scenario : c.scenarios) {
    const Drive d = load_drive(scenario, c);
    const auto& A = d.a();
    const auto& B = d.b();
    for (int single = 0; single < 2; ++single) {
      for (int threads : {1, c.threads}) {
        odometry::OdometryResult r;
        std::vector<double> secs;
        for (int rep = 0; rep < c.bench.repeats; ++rep) {
          const auto t0 = std::chrono::steady_clock::now();
          r = in_arena(threads, [&] {
            return single ? odometry::run_single_odometry(A.frames, A.timestamps)
                          : odometry::run_odometry(A.frames, A.timestamps, B.frames, B.timestamps,
                                                   d.truth);
          });
          secs.push_back(seconds_since(t0));
        }
        std::sort(secs.begin(), secs.end());
        // Drift against the trajectory: a's poses relative to its first paired frame.
        std::vector<Isometry3d> gt;
        std::vector<Isometry3d> est;
        for (const auto& p : r.pairs) {
          gt.push_back(jeep_test::lidar_pose(d.data, 0, A.timestamps[p.a]));
          est.push_back(r.poses_a[p.a]);
        }
        double path = 0.0;
        std::vector<double> cumulative{0.0};
        for (std::size_t k = 1; k < gt.size(); ++k) {
          path += (gt[k].translation() - gt[k - 1].translation()).norm();
          cumulative.push_back(path);
        }
        const Isometry3d rel_gt = gt.front().inverse() * gt.back();
        const Isometry3d rel = est.front().inverse() * est.back();
        const double end_drift = 100.0 * (rel.translation() - rel_gt.translation()).norm() / path;
        const double rot_drift =
            ulc::rotation_error_rad(rel_gt.linear(), rel.linear()) / kDeg / path * 100.0;
        // Segments of 100 pairs (10 s at 10 Hz), every 10 pairs.
        std::vector<double> seg;
        const std::size_t L = std::min<std::size_t>(100, gt.size() - 1);
        for (std::size_t k = 0; k + L < gt.size(); k += 10) {
          const Isometry3d g = gt[k].inverse() * gt[k + L];
          const Isometry3d e = est[k].inverse() * est[k + L];
          const double len = cumulative[k + L] - cumulative[k];
          if (len > 1.0) seg.push_back(100.0 * (e.translation() - g.translation()).norm() / len);
        }
        table.add_row({scenario, single ? "single (a)" : "multi (a+b)", Cell::integer(threads),
                       Cell::integer(static_cast<long long>(r.pairs.size())), Cell::num(path, 1),
                       Cell::num(end_drift, 3), Cell::num(jeep_test::median(seg), 3),
                       Cell::num(rot_drift, 4),
                       Cell::num(r.pairs.size() / ulc_bench::median_of_sorted(secs), 2)});
      }
    }
  }
  emit(table, "bench_jeep_odometry", c,
       {{"scenarios", scenario_list(c)}, {"seconds", Cell::num(c.seconds, 1)}},
       {{"segment_drift_pct", "median over 100-pair segments of |t_err| / path length"},
        {"pairs_per_s", "median over --repeats runs, frames already in memory"}});
}

// ---------------------------------------------------------------------------------------------
// (d) registration speed

void registration(Config c) {
  const std::string scenario = c.scenarios.empty() ? "64-32" : c.scenarios[0];
  c.seconds = std::min(c.seconds, 1.0);  // one frame pair is enough: a short, separate cache
  const Drive d = load_drive(scenario, c);
  const auto& target_frame = d.a().frames[d.pairs[0].a];
  const auto& source_frame = d.b().frames[d.pairs[0].b];
  const Isometry3d initial = disturbance_for(d, c, 0, 2.0, 0.3);
  ulc::RegistrationOptions o;  // the same gate, kernel and cap for every variant
  o.max_correspondence_distance = 1.0;
  o.kernel = ulc::RobustKernel::geman_mcclure(0.1);
  o.max_iterations = 30;
  ulc_bench::Table table({"case", "threads", "points", "median_ms", "per_item_ns", "detail"});
  for (double source_voxel : {0.25, 0.5, 1.0}) {
    const auto target_cloud = ulc::voxel_downsample(target_frame, 0.2).cloud;
    const auto source = ulc::voxel_downsample(source_frame, source_voxel).cloud;
    for (int threads : {1, c.threads}) {
      ulc::PlaneCloud<float> target;
      const double build = ulc_bench::median_seconds(c.bench.repeats, [&] {
        in_arena(threads, [&] { target = ulc::PlaneCloud<float>(target_cloud); });
      });
      ulc::RegistrationResult<double> r;
      const double reg = ulc_bench::median_seconds(c.bench.repeats, [&] {
        r = in_arena(threads,
                     [&] { return ulc::register_point_to_plane(source, target, initial, o); });
      });
      const auto e = ulc::pose_error(d.truth, r.pose);
      std::ostringstream detail;
      detail << ulc::to_string(r.status) << ", " << r.iterations << " searches, "
             << r.solver_iterations << " steps, e_rot " << e.rotation_deg << " deg, e_trans "
             << 100 * e.translation_m << " cm";
      if (source_voxel == 0.25)
        table.add_row({"PlaneCloud build (kd-tree + normals)", Cell::integer(threads),
                       Cell::integer(static_cast<long long>(target_cloud.size())),
                       Cell::num(1e3 * build, 2), Cell::num(1e9 * build / target_cloud.size(), 0),
                       "HDL-64E frame at 0.2 m"});
      table.add_row({"ICP 32 -> 64, source voxel " + std::to_string(source_voxel).substr(0, 4),
                     Cell::integer(threads), Cell::integer(static_cast<long long>(source.size())),
                     Cell::num(1e3 * reg, 2),
                     Cell::num(1e9 * reg / (source.size() * std::max(1, r.iterations)), 0),
                     detail.str()});
    }
  }
  // The two targets' query cost on the same points: kd-tree PlaneCloud and voxel LocalMap.
  {
    const auto target_cloud = ulc::voxel_downsample(target_frame, 0.2).cloud;
    const auto queries = ulc::voxel_downsample(source_frame, 0.3).cloud;
    const ulc::PlaneCloud<float> kd(target_cloud);
    odometry::LocalMap<float> map;
    map.insert(target_cloud.points, ulc::Vec3d::Zero());
    std::vector<ulc::Vec3d> q;
    for (const auto& p : queries.points) q.push_back(initial * p.cast<double>());
    for (int which = 0; which < 2; ++which) {
      std::size_t found = 0;
      const double t = ulc_bench::median_seconds(c.bench.repeats, [&] {
        ulc::PlaneMatch m;
        found = 0;
        for (const auto& x : q)
          found += which == 0 ? kd.find_plane(x, 1.0, m) : map.find_plane(x, 1.0, m);
      });
      table.add_row(
          {which == 0 ? "find_plane, PlaneCloud (kd-tree)" : "find_plane, LocalMap (voxels)",
           Cell::integer(1), Cell::integer(static_cast<long long>(q.size())), Cell::num(1e3 * t, 2),
           Cell::num(1e9 * t / q.size(), 0), std::to_string(found) + " matched within 1 m"});
    }
    const double insert = ulc_bench::median_seconds(c.bench.repeats, [&] {
      odometry::LocalMap<float> m;
      m.insert(target_cloud.points, ulc::Vec3d::Zero());
    });
    table.add_row({"LocalMap insert (planes fitted)", Cell::integer(c.threads),
                   Cell::integer(static_cast<long long>(target_cloud.size())),
                   Cell::num(1e3 * insert, 2), Cell::num(1e9 * insert / target_cloud.size(), 0),
                   "one HDL-64E frame into an empty map"});
  }
  emit(table, "bench_jeep_registration", c,
       {{"scenario", scenario},
        {"gate_m", Cell::num(1.0, 1)},
        {"kernel", "geman_mcclure 0.1"},
        {"max_iterations", Cell::integer(30)}},
       {{"peers", "PCL and Open3D not installed (dpkg -l libpcl-dev libopen3d-dev): not run"}});
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app(
      "JEEP, scan-scan, odometry and ICP on simulated drives (modes: --accuracy "
      "--separation --robustness --frames-sweep --odometry --registration; see the top "
      "of bench/bench_jeep.cpp)",
      "bench_jeep");
  ulc_bench::add_options(app, c.bench);
  for (const char* mode :
       {"accuracy", "separation", "robustness", "odometry", "frames-sweep", "registration"})
    app.add_flag_callback(
        std::string("--") + mode, [&c, mode] { c.mode = mode; },
        std::string("run the ") + mode + " bench (default: registration)");
  app.add_option("--scenarios", c.scenarios, "scenarios (default: the mode's)")
      ->delimiter(',')
      ->type_name("A,B,...");
  app.add_option("--starts", c.starts, "starts per scenario (default: the mode's)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  app.add_option("--frames", c.frames, "frame pairs K (default 5)")
      ->type_name("K")
      ->check(CLI::PositiveNumber);
  app.add_option("--seconds", c.seconds, "simulated drive (default 20)")->type_name("S");
  app.add_option("--seed", c.seed, "disturbance seed (default 1)")->type_name("N");
  ulc_bench::add_threads_option(app, c.threads);
  app.add_option("--cache", c.cache, "folder of the cached drives (default /tmp/ulc_jeep_cache)")
      ->type_name("DIR");
  app.add_option("--png", c.png_dir, "robustness and frames-sweep heat maps as PNG")
      ->type_name("DIR");
  app.add_flag("--one-way", c.one_way, "JEEP without its two-way step");
  app.add_option("--methods", c.methods,
                 "--accuracy's rows, in this order (default jeep,scan-scan,gicp,ndt)")
      ->delimiter(',')
      ->type_name("A,B,...")
      ->check(CLI::IsMember({"jeep", "scan-scan", "gicp", "ndt"}));
  CLI11_PARSE(app, argc, argv);
  const bool repeats_given = app.count("--repeats") > 0;
  if (c.mode == "accuracy") {
    accuracy(c);
  } else if (c.mode == "separation") {
    separation(c);
  } else if (c.mode == "robustness") {
    robustness(c);
  } else if (c.mode == "frames-sweep") {
    frames_sweep(c);
  } else if (c.mode == "odometry") {
    if (!repeats_given) c.bench.repeats = 1;  // a whole drive per repeat
    odometry_bench(c);
  } else {
    registration(c);
  }
  return 0;
}
