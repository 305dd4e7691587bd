// bench_hots: HOTS (odometry over the whole drive, hierarchical BA, pose graph, time
// synchronisation) after JEEP, on simulated rig drives (ulc::sim), against the ground truth.
//
//   bench_hots --accuracy    [--scenarios 64-32,...] [--seconds 60] [--runs 10]
//   bench_hots --time-offset [--scenarios 64-32,64-horizon] [--seconds 60] [--runs 10]
//                            [--spread-png PREFIX] [--offset-ms 50]
//   common: [--decimation 1] [--threads 2] [--jeep-decides]
//           [--first-run 0] [--json]
//           [--layers N] [--trajectory PREFIX] [--hots NAME=VALUE ...] [--steering-ramp M]
//           [--no-traffic]
//   --layers N: HOTS's hierarchy layers (default: HierarchyOptions' 3, the paper's).
//   --trajectory PREFIX: per run, PREFIX_<scenario>_run<k>.csv with the base's true, odometry and
//   HOTS positions, each one's frame-to-frame motion error and orientation error (to see where a
//   drift comes from).
//   --hots NAME=VALUE (repeatable): one of HOTS's numeric options by name, for experiments
//   without a rebuild: plane_voxel, plane_depth, plane_ratio, plane_distance, frame_voxel,
//   submap_voxel, boundary_registration (0/1), boundary_radius_m, boundary_sigma_m,
//   boundary_sigma_rad, extrinsic_sigma_m, extrinsic_sigma_rad, link_min_layer, rounds, window,
//   synchronise_time (0/1).
//   --steering-ramp M: the simulated vehicle follows its route averaged over M metres, so that
//   yaw rate and body roll ramp into turns (ulc::sim::MotionSpec::steering_ramp_m; default 0:
//   they step where a line meets an arc). --no-traffic: no oncoming cars.
//   --jeep-decides: a failed JEEP ends the run (by default, as in the pipeline, a JEEP that was
//   rejected or did not settle hands its extrinsic to HOTS, whose cross links judge it:
//   CalibrateOptions::tuning.hypotheses.hots_judges_jeep; the stderr line says "judged").
//
// Each run simulates the drive with seed = run index + 1 (runs --first-run onwards), disturbs the
// truth by 5 deg about a random axis and 2 m in a random direction (seeded by the run), runs JEEP
// (calibrate_pair, stages jeep, K = 5 pairs from the first frame), then the pipeline's HOTS stage
// by hand (the same odometry and refine options as ulc::CalibrateOptions' defaults) so that the
// poses are at hand for the trajectory error. Success: HOTS ok and e_rot < 1 deg and e_trans < 10
// cm. Medians are over all runs, failures included. --time-offset runs each scenario with the
// target's clock 50 ms behind (the paper's figure) and with no offset (--offset-ms X: only X
// ms; the no-offset runs are the same as --accuracy's). --spread-png PREFIX
// writes run 0's spread-against-offset curve (HOTS's last time synchronisation pass) of each
// scenario and offset to PREFIX_<scenario>_<offset_ms>ms.png: x the candidate offset in ms,
// y the corrected spread in cm^2, a solid green line at the true offset and a dashed red one at
// HOTS's final estimate (support/curve_png.hpp).
// ATE: RMS translation error of the base LiDAR's poses (odometry's, then HOTS's) against the
// simulator's trajectory, both in the base frame at its first timestamp; ate_aligned_*: the same
// after the best rigid alignment of the whole trajectory (the TUM/evo definition). The stderr line
// of each run adds the relative pose error (RMS translation error of the motion over 1, 5, 25, 125,
// 250, 500 frames), odometry -> HOTS: which time scales HOTS improves, and the wall time of
// HOTS's phases (RefineStatistics: prepare, hierarchy, links, graph, sync, sequence).
// A 60 s full-rate drive holds every frame in memory (several GB for 64-beam rigs):
// --decimation N keeps every Nth point.
#include <tbb/task_arena.h>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "../tests/jeep/jeep_test_util.hpp"
#include "hots/hots.hpp"
#include "odometry/run_odometry.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/pipeline.hpp"
#include "support/bench_util.hpp"
#include "support/curve_png.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/sim/simulate.hpp"

namespace {

using ulc::Isometry3d;
using ulc_bench::Cell;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct Config {
  std::string mode = "accuracy";
  std::vector<std::string> scenarios;
  double seconds = 60.0;
  std::size_t runs = 10;
  std::size_t first_run = 0;  ///< --first-run: runs first_run .. first_run + runs - 1
  unsigned decimation = 1;
  int threads = 2;
  std::string spread_png;        ///< prefix of the spread curve pictures; empty: none
  bool hots_judges_jeep = true;  ///< off with --jeep-decides
  double pre_shift_s = 0.0;      ///< --pre-shift-ms
  bool no_traffic = false;       ///< --no-traffic: the scenario without its oncoming cars
  double steering_ramp_m = 0.0;  ///< --steering-ramp M: MotionSpec::steering_ramp_m
  int layers = 0;                ///< --layers: HOTS hierarchy layers; 0: the default
  std::string trajectory;        ///< --trajectory PREFIX: per-frame poses of each run, as CSV
  std::vector<std::string> hots_settings;       ///< --hots NAME=VALUE, applied in order
  std::vector<double> offsets_s = {0.05, 0.0};  ///< --time-offset's offsets (--offset-ms X: X)
  ulc_bench::Options bench;
};

/// --hots NAME=VALUE: one of HOTS's numeric options by name (experiments without a rebuild).
void apply_hots_setting(hots::RefineOptions& o, const std::string& setting) {
  const auto eq = setting.find('=');
  const std::string name = setting.substr(0, eq);
  const double v = eq == std::string::npos ? 0.0 : std::atof(setting.c_str() + eq + 1);
  auto& planes = o.hierarchy.ba.planes;
  const auto as_int = [&] { return static_cast<int>(v); };
  const std::vector<std::pair<const char*, std::function<void()>>> setters = {
      {"plane_voxel", [&] { planes.voxel_size = v; }},
      {"plane_depth", [&] { planes.max_depth = as_int(); }},
      {"plane_ratio", [&] { planes.max_eigen_ratio = v; }},
      {"plane_distance", [&] { planes.max_distance = v; }},
      {"frame_voxel", [&] { o.frame_voxel = v; }},
      {"submap_voxel", [&] { o.hierarchy.submap_voxel = v; }},
      {"boundary_bridges", [&] { o.boundary_bridges = v != 0.0; }},
      {"bridge_huber", [&] { o.bridge_huber = v; }},
      {"boundary_registration", [&] { o.boundary_registration = v != 0.0; }},
      {"boundary_radius_m", [&] { o.boundary_radius_m = v; }},
      {"boundary_sigma_m", [&] { o.boundary_sigma_m = v; }},
      {"boundary_sigma_rad", [&] { o.boundary_sigma_rad = v; }},
      {"extrinsic_sigma_m", [&] { o.extrinsic_sigma_m = v; }},
      {"extrinsic_sigma_rad", [&] { o.extrinsic_sigma_rad = v; }},
      {"link_min_layer", [&] { o.links.min_layer = as_int(); }},
      {"rounds", [&] { o.hierarchy.ba.rounds = as_int(); }},
      {"window", [&] { o.hierarchy.window = static_cast<std::size_t>(v); }},
      {"sweep_parts", [&] { o.hierarchy.sweep_parts = static_cast<int>(v); }},
      {"end_knot", [&] { o.hierarchy.end_knot = v != 0.0; }},
      {"end_knot_factor", [&] { o.hierarchy.end_knot_factor = v != 0.0; }},
      {"synchronise_time", [&] { o.synchronise_time = v != 0.0; }},
  };
  for (const auto& [key, set] : setters)
    if (name == key) return set();
  std::cerr << "bench_hots: unknown --hots setting '" << name << "'\n";
  std::exit(2);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Peak resident memory of this process so far (VmHWM), MiB; 0 when /proc cannot tell.
double peak_memory_mib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  return 0.0;
}

/// RMS translation error of `est` against the simulator's poses of LiDAR `lidar`, both
/// expressed in that LiDAR's frame at its first timestamp.
double ate(const ulc::sim::Dataset& d, std::size_t lidar, const std::vector<Isometry3d>& est) {
  const auto& t = d.lidars[lidar].timestamps;
  const Isometry3d origin = jeep_test::lidar_pose(d, lidar, t.front()).inverse();
  double sum = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k)
    sum += ((origin * jeep_test::lidar_pose(d, lidar, t[k])).translation() - est[k].translation())
               .squaredNorm();
  return std::sqrt(sum / static_cast<double>(t.size()));
}

/// The same RMS after the rigid motion that best aligns the estimate with the truth (Horn's
/// closed form, as the TUM RGB-D benchmark and evo define the ATE): free of the error that a
/// small rotation at the first frame spreads along the whole drive.
double ate_aligned(const ulc::sim::Dataset& d, std::size_t lidar,
                   const std::vector<Isometry3d>& est) {
  const auto& t = d.lidars[lidar].timestamps;
  const double n = static_cast<double>(t.size());
  std::vector<ulc::Vec3d> g, e;
  ulc::Vec3d gm = ulc::Vec3d::Zero(), em = ulc::Vec3d::Zero();
  for (std::size_t k = 0; k < t.size(); ++k) {
    g.push_back(jeep_test::lidar_pose(d, lidar, t[k]).translation());
    e.push_back(est[k].translation());
    gm += g.back() / n;
    em += e.back() / n;
  }
  Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < g.size(); ++k) W += (g[k] - gm) * (e[k] - em).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(W, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1.0;
  const Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
  double sum = 0.0;
  for (std::size_t k = 0; k < g.size(); ++k) sum += (R * (e[k] - em) + gm - g[k]).squaredNorm();
  return std::sqrt(sum / n);
}

/// RMS translation error (m) of the relative motion over `lag` frames of `est` against the
/// simulator's (the relative pose error): where along the time scale a trajectory's error lives.
double rpe(const ulc::sim::Dataset& d, std::size_t lidar, const std::vector<Isometry3d>& est,
           std::size_t lag) {
  const auto& t = d.lidars[lidar].timestamps;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k + lag < t.size(); ++k, ++n) {
    const Isometry3d truth = jeep_test::lidar_pose(d, lidar, t[k]).inverse() *
                             jeep_test::lidar_pose(d, lidar, t[k + lag]);
    sum += (truth.inverse() * est[k].inverse() * est[k + lag]).translation().squaredNorm();
  }
  return n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

/// "lag 1: odometry -> HOTS cm, lag 5: ..." for the stderr log.
std::string rpe_line(const ulc::sim::Dataset& d, const std::vector<Isometry3d>& odometry,
                     const std::vector<Isometry3d>& refined) {
  std::ostringstream s;
  s << "RPE (cm)";
  for (const std::size_t lag : {1, 5, 25, 125, 250, 500})
    if (lag < odometry.size())
      s << ", lag " << lag << ": " << 100 * rpe(d, 0, odometry, lag) << " -> "
        << 100 * rpe(d, 0, refined, lag);
  return s.str();
}

/// Per frame of the base: time, the truth's, the odometry's and HOTS's positions (in the base's
/// frame at its first timestamp), each one's frame-to-frame motion error (m) and each one's
/// orientation error (deg, log(R_true^T R_est) in the true LiDAR frame: x roll, y pitch, z yaw
/// for a forward-looking base), as CSV.
void write_trajectory(const std::string& path, const ulc::sim::Dataset& d,
                      const std::vector<Isometry3d>& odometry,
                      const std::vector<Isometry3d>& refined) {
  std::ofstream out(path);
  const auto& t = d.lidars[0].timestamps;
  const Isometry3d origin = jeep_test::lidar_pose(d, 0, t.front()).inverse();
  out << "t,truth_x,truth_y,truth_z,odo_x,odo_y,odo_z,hots_x,hots_y,hots_z,odo_step_err,"
         "hots_step_err,odo_rot_x_deg,odo_rot_y_deg,odo_rot_z_deg,hots_rot_x_deg,hots_rot_y_deg,"
         "hots_rot_z_deg\n";
  for (std::size_t k = 0; k < t.size(); ++k) {
    const Isometry3d g = origin * jeep_test::lidar_pose(d, 0, t[k]);
    auto step_error = [&](const std::vector<Isometry3d>& e) {
      if (k == 0) return 0.0;
      const Isometry3d g0 = origin * jeep_test::lidar_pose(d, 0, t[k - 1]);
      return ((g0.inverse() * g).inverse() * e[k - 1].inverse() * e[k]).translation().norm();
    };
    out << t[k] << "," << g.translation().x() << "," << g.translation().y() << ","
        << g.translation().z() << "," << odometry[k].translation().x() << ","
        << odometry[k].translation().y() << "," << odometry[k].translation().z() << ","
        << refined[k].translation().x() << "," << refined[k].translation().y() << ","
        << refined[k].translation().z() << "," << step_error(odometry) << ","
        << step_error(refined);
    for (const auto* e : {&odometry, &refined}) {
      const ulc::Vec3d w = ulc::so3_log(Eigen::Matrix3d(g.linear().transpose() * (*e)[k].linear()));
      out << "," << w.x() / kDeg << "," << w.y() / kDeg << "," << w.z() / kDeg;
    }
    out << "\n";
  }
  std::cerr << "bench_hots: wrote " << path << "\n";
}

struct Run {
  bool jeep_ok = false, hots_ok = false;
  bool judged_by_hots = false;  ///< JEEP failed and HOTS ran from its extrinsic
  std::string status;
  ulc::PoseError jeep_error, hots_error, sync_error;
  double dt_error_s = 0.0, sync_dt_error_s = 0.0;
  double ate_odometry = 0.0, ate_hots = 0.0;
  double ate_aligned_odometry = 0.0, ate_aligned_hots = 0.0;
  std::string rpe;  ///< rpe_line of odometry and HOTS
  hots::SequenceExtrinsicResult sequence;
  std::string links;  ///< "cross k/n, boundaries k/n": HOTS's registrations kept
  double sequence_s = 0.0;
  double odometry_s = 0.0, hots_s = 0.0;
  double true_offset_s = 0.0, hots_offset_s = 0.0;
  std::vector<std::pair<double, double>> spread_curve;  ///< (offset s, spread m^2), HOTS's
};

Run one_run(const std::string& scenario, double offset_s, std::size_t run, const Config& c) {
  Run out;
  auto spec = *ulc::sim::scenario(scenario);
  if (offset_s != 0.0) ulc::sim::set_clock_offset(spec, spec.pairs.at(0).target, offset_s);
  if (c.no_traffic) spec.traffic_per_km = 0.0;
  spec.motion.steering_ramp_m = c.steering_ramp_m;
  ulc::sim::SimulationOptions so;
  so.seconds = c.seconds;
  so.seed = run + 1;
  so.decimation = c.decimation;
  const ulc::sim::Dataset d = ulc::sim::simulate(spec, so).dataset;
  const auto& a = d.lidars.at(0);
  const auto& b = d.lidars.at(1);
  // --pre-shift-ms: b's timestamps moved by that much before every stage (an experiment: how the
  // offset's estimate depends on what the stages before HOTS assume).
  std::vector<double> times_b = b.timestamps;
  for (double& t : times_b) t += c.pre_shift_s;
  const Isometry3d truth = d.pairs.at(0).T_base_target;
  const double true_offset = d.pairs.at(0).time_offset_s - c.pre_shift_s;
  out.true_offset_s = true_offset;
  std::mt19937_64 rng(1000003ULL * (run + 1));
  const Isometry3d initial = jeep_test::disturbed(truth, rng, 5.0 * kDeg, 2.0);

  tbb::task_arena arena(c.threads);
  arena.execute([&] {
    ulc::CalibrateOptions o;
    o.stages = {ulc::Stage::jeep};
    o.initial = initial;
    // HOTS, run next, estimates the clock offset: JEEP's own result need not vouch for one.
    o.tuning.vouch.enabled = false;
    if (c.layers > 0) o.tuning.hots.hierarchy.layers = c.layers;
    for (const auto& setting : c.hots_settings) apply_hots_setting(o.tuning.hots, setting);
    const auto j = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, times_b, o);
    out.status = ulc::to_string(j.status);
    out.jeep_ok = j.success;
    const Isometry3d C = j.jeep ? j.jeep->extrinsic : initial;
    out.jeep_error = ulc::pose_error(truth, C);
    out.hots_error = out.sync_error = out.jeep_error;
    out.dt_error_s = out.sync_dt_error_s = true_offset;
    // As the pipeline does (CalibrateOptions::tuning.hypotheses.hots_judges_jeep): a JEEP that was
    // rejected or did not settle hands its extrinsic to HOTS, whose cross links judge it.
    out.judged_by_hots = !j.success && c.hots_judges_jeep && j.jeep &&
                         ulc::calibrate_detail::hots_can_judge(*j.jeep);
    if (!j.success && !out.judged_by_hots) return;
    auto t0 = std::chrono::steady_clock::now();
    const auto odo =
        odometry::run_odometry(a.frames, a.timestamps, b.frames, times_b, C, o.tuning.odometry);
    out.odometry_s = seconds_since(t0);
    if (!ulc::calibrate_detail::odometry_usable(odo)) {
      out.status = std::string("odometry_") + odometry::to_string(odo.status);
      return;
    }
    out.ate_odometry = ate(d, 0, odo.poses_a);
    out.ate_aligned_odometry = ate_aligned(d, 0, odo.poses_a);
    t0 = std::chrono::steady_clock::now();
    const auto h =
        hots::refine(ulc::make_sequence(a.frames, a.timestamps, odo.poses_a),
                     ulc::make_sequence(b.frames, times_b, odo.poses_b), C, o.tuning.hots);
    out.hots_s = seconds_since(t0);
    out.status = std::string("hots_") + hots::to_string(h.status);
    out.hots_ok = h.ok();
    out.sequence = h.statistics.sequence;  // the trust check's figures, whatever the status
    const auto& st = h.statistics;
    out.links = "cross " + std::to_string(st.cross_links) + "/" +
                std::to_string(st.cross_links_attempted) + ", boundaries " +
                std::to_string(st.boundary_links) + "/" + std::to_string(st.boundary_factors) +
                ", bridged " + std::to_string(st.boundary_bridges);
    // Where HOTS's time goes (RefineStatistics' phase clocks).
    std::ostringstream phases;
    phases << "; phases s: prepare " << st.prepare_seconds << ", hierarchy " << st.hierarchy_seconds
           << ", links " << st.links_seconds << ", graph " << st.graph_seconds << ", sync "
           << st.sync_seconds << ", sequence " << st.sequence_seconds << "; windows " << st.windows
           << " (" << st.failed_windows << " failed), planes " << st.planes;
    out.links += phases.str();
    if (!h.ok()) return;
    out.hots_error = ulc::pose_error(truth, h.extrinsic);
    out.dt_error_s = h.time_offset_s - true_offset;
    out.hots_offset_s = h.time_offset_s;
    out.spread_curve = h.spread_curve;
    out.sync_error = ulc::pose_error(truth, h.statistics.sync_extrinsic);
    out.sequence = h.statistics.sequence;
    out.sequence_s = h.statistics.sequence_seconds;
    out.sync_dt_error_s = h.statistics.sync_time_offset_s - true_offset;
    out.ate_hots = ate(d, 0, h.poses_a);
    out.ate_aligned_hots = ate_aligned(d, 0, h.poses_a);
    out.rpe = rpe_line(d, odo.poses_a, h.poses_a);
    if (!c.trajectory.empty())
      write_trajectory(c.trajectory + "_" + scenario + "_run" + std::to_string(run) + ".csv", d,
                       odo.poses_a, h.poses_a);
  });
  return out;
}

void emit(const ulc_bench::Table& table, const std::string& name, const Config& c,
          const std::vector<std::pair<std::string, Cell>>& parameters,
          const std::vector<std::pair<std::string, Cell>>& notes) {
  ulc_bench::emit(std::cout, table, c.bench.json, name, 1, parameters, notes);
}

/// Run `r`'s spread curve to PREFIX_<scenario>_<offset_ms>ms.png (see the header comment).
void write_spread_png(const Run& r, const std::string& scenario, double offset_s, const Config& c) {
  const std::string path = c.spread_png + "_" + scenario + "_" +
                           std::to_string(static_cast<long long>(std::lround(offset_s * 1e3))) +
                           "ms.png";
  ulc_bench::CurvePlot plot;
  plot.series.push_back({"spread", {}});
  for (const auto& [dt, spread] : r.spread_curve)
    plot.series.back().points.emplace_back(dt * 1e3, spread * 1e4);
  plot.markers.push_back({"true offset", r.true_offset_s * 1e3, false});
  if (r.hots_ok) plot.markers.push_back({"HOTS estimate", r.hots_offset_s * 1e3, true});
  if (ulc_bench::write_curve_png(path, plot))
    std::cerr << "bench_hots: wrote " << path << "\n";
  else
    std::cerr << "bench_hots: no spread curve written to " << path
              << " (HOTS did not synchronise, or the file cannot be written)\n";
}

void bench(Config c) {
  const bool offsets = c.mode == "time-offset";
  if (c.scenarios.empty())
    c.scenarios = offsets ? std::vector<std::string>{"64-32", "64-horizon"}
                          : std::vector<std::string>{"64-32",      "32-16",   "horizon-tele",
                                                     "64-horizon", "32-avia", "64-tele"};
  const std::vector<double> offset_list = offsets ? c.offsets_s : std::vector<double>{0.0};
  ulc_bench::Table table({"scenario",
                          "offset_ms",
                          "runs",
                          "jeep_success_pct",
                          "hots_success_pct",
                          "jeep_e_rot_deg",
                          "sync_e_rot_deg",
                          "hots_e_rot_deg",
                          "jeep_e_trans_cm",
                          "sync_e_trans_cm",
                          "hots_e_trans_cm",
                          "sync_dt_error_ms",
                          "dt_error_ms",
                          "ate_odometry_cm",
                          "ate_hots_cm",
                          "ate_aligned_odometry_cm",
                          "ate_aligned_hots_cm",
                          "offset_untrusted",
                          "odometry_s",
                          "hots_s"});
  for (const auto& scenario : c.scenarios) {
    if (!ulc::sim::scenario(scenario)) {
      std::cerr << "bench_hots: unknown scenario '" << scenario << "'\n";
      std::exit(2);
    }
    for (const double offset : offset_list) {
      std::vector<double> jr, hr, jt, ht, dt, ao, ah, aao, aah, so, sh, yr, yt, ydt;
      std::size_t jeep_ok = 0, hots_ok = 0, untrusted = 0;
      for (std::size_t run = c.first_run; run < c.first_run + c.runs; ++run) {
        const Run r = one_run(scenario, offset, run, c);
        const bool j_success = r.jeep_ok && ulc::is_calibration_success(r.jeep_error);
        const bool h_success = r.hots_ok && ulc::is_calibration_success(r.hots_error);
        jeep_ok += j_success ? 1 : 0;
        hots_ok += h_success ? 1 : 0;
        untrusted += r.sequence.time_offset_checked && !r.sequence.time_offset_trusted ? 1 : 0;
        jr.push_back(r.jeep_error.rotation_deg);
        hr.push_back(r.hots_error.rotation_deg);
        jt.push_back(r.jeep_error.translation_m);
        ht.push_back(r.hots_error.translation_m);
        dt.push_back(std::abs(r.dt_error_s));
        yr.push_back(r.sync_error.rotation_deg);
        yt.push_back(r.sync_error.translation_m);
        ydt.push_back(std::abs(r.sync_dt_error_s));
        ao.push_back(r.ate_odometry);
        ah.push_back(r.ate_hots);
        aao.push_back(r.ate_aligned_odometry);
        aah.push_back(r.ate_aligned_hots);
        so.push_back(r.odometry_s);
        sh.push_back(r.hots_s);
        if (!c.bench.json)
          std::cerr << "  " << scenario << " offset " << offset * 1e3 << " ms run " << run << ": "
                    << r.status << (r.judged_by_hots ? " (JEEP failed, judged by HOTS)" : "")
                    << "; JEEP " << r.jeep_error.rotation_deg << " deg "
                    << r.jeep_error.translation_m * 100 << " cm; sync " << r.sync_error.rotation_deg
                    << " deg " << r.sync_error.translation_m * 100 << " cm dt error "
                    << r.sync_dt_error_s * 1e3 << " ms; HOTS " << r.hots_error.rotation_deg
                    << " deg " << r.hots_error.translation_m * 100 << " cm, dt error "
                    << r.dt_error_s * 1e3 << " ms, ATE " << r.ate_odometry * 100 << " -> "
                    << r.ate_hots * 100 << " cm (aligned " << r.ate_aligned_odometry * 100 << " -> "
                    << r.ate_aligned_hots * 100 << " cm) (" << r.odometry_s << " + " << r.hots_s
                    << " s); links " << r.links << "; sequence: joint dt "
                    << r.sequence.joint_time_offset_s * 1e3 << " ms sigma "
                    << r.sequence.time_sigma_s * 1e3 << " ms observability "
                    << r.sequence.time_observability << " adopted "
                    << r.sequence.time_offset_refined << " halves "
                    << r.sequence.half_time_offset_s[0] * 1e3 << ", "
                    << r.sequence.half_time_offset_s[1] * 1e3 << " ms trusted "
                    << r.sequence.time_offset_trusted << " (" << r.sequence.time_offset_doubt
                    << "), " << r.sequence.iterations << " matchings, " << r.sequence.source_points
                    << " points, " << r.sequence_s << " s; " << r.rpe << "\n";
        if (offsets && run == c.first_run && !c.spread_png.empty())
          write_spread_png(r, scenario, offset, c);
      }
      const double n = static_cast<double>(c.runs);
      using jeep_test::median;
      table.add_row({scenario,
                     Cell::num(offset * 1e3, 0),
                     Cell::integer(static_cast<long long>(c.runs)),
                     Cell::num(100.0 * static_cast<double>(jeep_ok) / n, 1),
                     Cell::num(100.0 * static_cast<double>(hots_ok) / n, 1),
                     Cell::num(median(jr), 4),
                     Cell::num(median(yr), 4),
                     Cell::num(median(hr), 4),
                     Cell::num(100 * median(jt), 2),
                     Cell::num(100 * median(yt), 2),
                     Cell::num(100 * median(ht), 2),
                     Cell::num(1e3 * median(ydt), 2),
                     Cell::num(1e3 * median(dt), 2),
                     Cell::num(100 * median(ao), 2),
                     Cell::num(100 * median(ah), 2),
                     Cell::num(100 * median(aao), 2),
                     Cell::num(100 * median(aah), 2),
                     Cell::integer(static_cast<long long>(untrusted)),
                     Cell::num(median(so), 2),
                     Cell::num(median(sh), 2)});
    }
  }
  std::string list;
  for (const auto& s : c.scenarios) list += (list.empty() ? "" : ",") + s;
  emit(table, offsets ? "bench_hots_time_offset" : "bench_hots_accuracy", c,
       {{"scenarios", list},
        {"seconds", Cell::num(c.seconds, 1)},
        {"runs", Cell::integer(static_cast<long long>(c.runs))},
        {"first_run", Cell::integer(static_cast<long long>(c.first_run))},
        {"decimation", Cell::integer(c.decimation)},
        {"threads", Cell::integer(c.threads)},
        {"disturbance", "5 deg about a random axis, 2 m in a random direction, before JEEP"}},
       {{"success", "status ok and e_rot < 1 deg and e_trans < 10 cm"},
        {"medians", "over all runs, failures included (a failed HOTS counts JEEP's error)"},
        {"dt_error", "|estimated - true clock offset|; the true offset when HOTS did not run"},
        {"ate",
         "RMS position error of the base's poses, first frames aligned; ate_aligned_*: "
         "after the best rigid alignment of the whole trajectory"},
        {"offset_untrusted",
         "runs whose HOTS refused its clock offset (time_offset_untrusted: a failure above)"},
        {"sync",
         "the time synchronisation's answer (spread minimum, eq:mean), before the "
         "whole-sequence step that gives HOTS's final extrinsic and offset"},
        {"peak_memory_mib", Cell::num(peak_memory_mib(), 0)}});
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app(
      "HOTS after JEEP on simulated drives, against the ground truth (modes: --accuracy, "
      "--time-offset; see the top of bench/bench_hots.cpp)",
      "bench_hots");
  ulc_bench::add_options(app, c.bench);
  app.add_flag_callback(
      "--accuracy", [&] { c.mode = "accuracy"; }, "accuracy mode (default)");
  app.add_flag_callback(
      "--time-offset", [&] { c.mode = "time-offset"; },
      "time-offset mode: target clock 50 ms behind, and no offset");
  app.add_option("--scenarios", c.scenarios, "scenarios (default: the mode's)")
      ->delimiter(',')
      ->type_name("A,B,...");
  app.add_option("--seconds", c.seconds, "simulated drive (default 60)")->type_name("S");
  app.add_option("--runs", c.runs, "runs per scenario (default 10)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  ulc_bench::add_first_run_option(app, c.first_run);
  app.add_option("--decimation", c.decimation, "keep every Nth point (default 1)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  ulc_bench::add_threads_option(app, c.threads);
  app.add_option("--spread-png", c.spread_png, "draw run 0's spread curves to PREFIX_...png")
      ->type_name("PREFIX");
  app.add_option_function<double>(
         "--offset-ms", [&](double ms) { c.offsets_s = {ms * 1e-3}; },
         "--time-offset: only this offset")
      ->type_name("X");
  app.add_option_function<double>(
         "--pre-shift-ms", [&](double ms) { c.pre_shift_s = ms * 1e-3; },
         "shift the target's timestamps before HOTS")
      ->type_name("X");
  app.add_option("--layers", c.layers, "HOTS's hierarchy layers (default 3)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  app.add_option("--trajectory", c.trajectory, "per run, PREFIX_<scenario>_run<k>.csv")
      ->type_name("PREFIX");
  app.add_option("--hots", c.hots_settings, "one of HOTS's numeric options (repeatable)")
      ->type_name("NAME=VALUE")
      ->allow_extra_args(false);
  app.add_option("--steering-ramp", c.steering_ramp_m, "route averaged over M metres")
      ->type_name("M");
  app.add_flag("--no-traffic", c.no_traffic, "no oncoming cars");
  app.add_flag_callback(
      "--jeep-decides", [&] { c.hots_judges_jeep = false; }, "a failed JEEP ends the run");
  CLI11_PARSE(app, argc, argv);
  bench(c);
  return 0;
}
