// bench_terra: speed of TERRA's pieces and of the whole two-step search, against the paper's
// kd-tree lookup and against the naive way (turn the cloud, rebuild the descriptor), measured in
// the same run; and, with --accuracy, TERRA against scancontext* on simulated rig pairs.
//
//   ./build/bench/bench_terra [--json] [--repeats N]
//   ./build/bench/bench_terra --accuracy [--pairs 64-32,32-16] [--samples 50] [--seed 1]
//                             [--lattice 10000] [--[no-]adaptive-d1] [--min-overlap 0.2]
//                             [--top-k 10] [--coarse-stride 10] [--d1 20] [--d2 5]
//                             [--alpha 2] [--mount-offset X,Y,Z] [--fpfh] [--threads 2] [--json]
//   ./build/bench/bench_terra --maps [--pairs 64-tele,...] [--starts 8] [--spacing 3]
//                             [--window 2] [--decimation 1] [--below-mask 100] [--seed 1]
//                             [--no-motion] [--threads 2] [--json]
//   ./build/bench/bench_terra --windows [--seed 1] [--pairs ...] [--starts 50] [--no-motion]
//   ./build/bench/bench_terra --landscape [--pairs 64-32,64-tele] [--samples 5] [--grid-step 10]
//                             [--png DIR]   (terra_landscape.hpp)
//
// Speed mode scenes: the synthetic crossroads of the tests (a 100k-point frame of an 80-beam
// LiDAR, and a 32-beam target turned and 0.5 m away), and a simulated 64-32 frame pair
// (HDL-64E and VLP-32C on one car, ulc::sim), the paper's reference task. Every timing is the
// median over --repeats runs, in a tbb::task_arena of the given thread count.
//
// Accuracy mode: for each pair scenario, --samples frame pairs spread along a simulated drive;
// the target frame is turned by a rotation uniform on SO(3) (seeded, terra::profile_case), so
// no method can lean on the mount being near the identity. Success: e_rot < 10 deg.
// --mount-offset X,Y,Z moves the target to the base's position plus this offset (metres, vehicle
// frame: x forward, along the drive; y left), keeping its orientation: the paper's ablation of
// TERRA against the mount's translation (its d1 figure). Each LiDAR's housing blocks the other's
// rays, so offsets under the housings' size leave the target blind. --fpfh adds the FPFH + RANSAC
// baseline (fpfh_baseline.hpp) on the same turned targets.
//
// Maps mode: for each pair scenario, --starts windows of --window seconds spread along a drive,
// the target's frames turned by a uniform random rotation per window; ulc::calibrate_pair
// (terra stage alone) with terra_source frames, maps and automatic on the same windows.
// Success: e_rot < 5 deg (also < 10 deg); a failed search counts as 180 deg. --no-motion turns
// the motion frame (pipeline/motion_frame.hpp) off, for the comparison.
//
// Windows mode (--windows), issue 34's protocol: the eight pairs of the paper's TERRA figure,
// 50 windows starting 1 s apart (from 1 s on) of --window seconds (default 2, the cap;
// the pipeline's default map window is 5), frames and automatic as in maps mode, and
// scancontext* on each window's first frame pair.
#include <tbb/task_arena.h>
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../tests/terra/terra_test_util.hpp"
#include "fpfh_baseline.hpp"
#include "pipeline/calibrate.hpp"
#include "support/bench_util.hpp"
#include "terra/terra.hpp"
#include "terra_landscape.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/sim/sim.hpp"

namespace {

using ulc_bench::Cell;
using Cloud = std::vector<ulc::Vec3d>;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

template <class F>
auto in_arena(int threads, F&& f) {
  tbb::task_arena arena(threads);
  return arena.execute(std::forward<F>(f));
}

/// The cube-map lookup queried one direction at a time (no batching): what batching saves.
struct OneByOne {
  const terra::Lattice& lattice;
  std::size_t size() const { return lattice.size(); }
  void nearest_batch(const ulc::Vec3d* q, std::size_t n, terra::LatticeIndex* out) const {
    for (std::size_t k = 0; k < n; ++k) out[k] = lattice.nearest(q[k]);
  }
};

/// The naive evaluation of one rotation: turn every target point, rebuild the descriptor,
/// compare. Returns the distance (to keep the work observable).
double naive_distance(const terra::Lattice& lattice, const terra::Descriptor<double>& base,
                      const Cloud& target, const ulc::Mat3d& R, Cloud& scratch) {
  scratch.resize(target.size());
  for (std::size_t i = 0; i < target.size(); ++i) scratch[i] = R * target[i];
  const auto g = terra::make_descriptor(lattice, scratch);
  return terra::descriptor_distance(base, g, terra::DistanceParams()).distance;
}

std::string fmt(double v, int decimals) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(decimals);
  out << v;
  return out.str();
}

struct Pair {
  std::string name;
  Cloud base, target;
  ulc::Mat3d R_base_target = ulc::Mat3d::Identity();
};

Cloud to_cloud(const ulc::PointCloud<float>& c) {
  Cloud out;
  out.reserve(c.size());
  for (const auto& p : c.points) out.push_back(p.cast<double>());
  return out;
}

/// Moves the target of the scenario's first pair to the base's position plus `offset` (vehicle
/// frame), keeping its orientation.
void move_target(ulc::sim::ScenarioSpec& spec, const ulc::Vec3d& offset) {
  const ulc::sim::LidarPair& lp = spec.pairs.front();
  const ulc::Vec3d base = spec.find(lp.base)->T_vehicle_lidar.translation();
  for (ulc::sim::LidarMount& m : spec.lidars)
    if (m.name == lp.target) m.T_vehicle_lidar.translation() = base + offset;
}

/// A scenario's first pair: its spec, the pair and its two LiDARs' indices in spec.lidars.
struct FirstPair {
  ulc::sim::ScenarioSpec spec;
  ulc::sim::LidarPair pair;
  std::size_t base = 0, target = 0;
};

/// The named scenario's first pair; nullopt (and `error` set) for an unknown or pairless one.
std::optional<FirstPair> first_pair(const std::string& name, std::string& error) {
  auto spec = ulc::sim::scenario(name);
  if (!spec || spec->pairs.empty()) {
    error = "unknown scenario '" + name + "'";
    return std::nullopt;
  }
  FirstPair fp{*spec, spec->pairs.front(), 0, 0};
  for (std::size_t i = 0; i < fp.spec.lidars.size(); ++i) {
    if (fp.spec.lidars[i].name == fp.pair.base) fp.base = i;
    if (fp.spec.lidars[i].name == fp.pair.target) fp.target = i;
  }
  return fp;
}

/// The truth of `pair` in a simulation's result; nullptr (and `error` set) when the simulation
/// failed or gave none.
const ulc::sim::PairTruth* simulated_truth(const ulc::sim::SimulationResult& result,
                                           const ulc::sim::LidarPair& pair, const std::string& name,
                                           std::string& error) {
  if (!result.ok()) {
    error = name + ": " + result.reason;
    return nullptr;
  }
  for (const auto& p : result.dataset.pairs)
    if (p.base == pair.base && p.target == pair.target) return &p;
  error = name + ": no ground truth for its pair";
  return nullptr;
}

/// Frame pairs of a simulated scenario's first pair, `samples` of them spread `spacing_s` apart
/// along the drive; the target frame nearest in time to each base frame. With `mount_offset`,
/// the target sits there from the base (move_target).
std::vector<Pair> simulated_pairs(const std::string& name, std::size_t samples, double spacing_s,
                                  std::uint64_t seed, std::string& error,
                                  const std::optional<ulc::Vec3d>& mount_offset = std::nullopt) {
  std::vector<Pair> out;
  auto fp = first_pair(name, error);
  if (!fp) return out;
  if (mount_offset) move_target(fp->spec, *mount_offset);
  const ulc::sim::ScenarioSpec& spec = fp->spec;
  const std::size_t base_index = fp->base, target_index = fp->target;
  ulc::sim::SimulationOptions options;
  options.seed = seed;
  options.seconds = spacing_s * static_cast<double>(samples) + 0.5;
  options.keep_frames = false;
  // Keep the base frames at the sample times and the target frames.
  std::map<std::size_t, ulc::PointCloud<float>> base_frames, target_frames;
  const double base_rate = spec.lidars[base_index].rate_hz;
  const auto stride = static_cast<std::size_t>(std::max(1.0, std::round(spacing_s * base_rate)));
  const auto sink = [&](const ulc::sim::FrameEvent& e) {
    if (e.lidar == base_index && e.frame % stride == 0) base_frames[e.frame] = e.cloud;
    // All target frames (~1 MB each): the nearest in time is chosen after the run, once the
    // timestamps and the pair's clock offset are known.
    if (e.lidar == target_index) target_frames[e.frame] = e.cloud;
    return true;
  };
  const auto result = ulc::sim::simulate(spec, options, sink);
  const ulc::sim::PairTruth* truth = simulated_truth(result, fp->pair, name, error);
  if (!truth) return out;
  const auto& ds = result.dataset;
  const auto& bt = ds.lidars[base_index].timestamps;
  const auto& tt = ds.lidars[target_index].timestamps;
  for (const auto& [k, cloud] : base_frames) {
    if (out.size() == samples) break;
    // Target frame nearest in time: t_base_clock = t_target_clock + time_offset_s.
    std::size_t best = 0;
    double best_dt = 1e9;
    for (std::size_t j = 0; j < tt.size(); ++j) {
      const double dt = std::fabs(tt[j] + truth->time_offset_s - bt[k]);
      if (dt < best_dt) best_dt = dt, best = j;
    }
    const auto it = target_frames.find(best);
    if (it == target_frames.end()) continue;
    Pair p;
    p.name = name;
    p.base = to_cloud(cloud);
    p.target = to_cloud(it->second);
    p.R_base_target = truth->T_base_target.linear();
    out.push_back(std::move(p));
  }
  if (out.size() < samples) error = name + ": only " + std::to_string(out.size()) + " frame pairs";
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return ulc_bench::median_of_sorted(v);
}

// ---------------------------------------------------------------------------------------------

int run_speed(const ulc_bench::Options& options) {
  const int repeats = options.repeats;
  ulc_bench::Table table({"case", "N", "threads", "median_ms", "per_item", "item", "detail"});

  // Scenes.
  Cloud frame = terra_test::scan(ulc::Mat3d::Identity(), ulc::Vec3d::Zero(), 80, 1800);  // ~100k
  frame.resize(std::min<std::size_t>(frame.size(), 100000));
  const Cloud base = terra_test::scan(ulc::Mat3d::Identity(), ulc::Vec3d::Zero(), 64, 1800);
  terra::SplitMix64 rng(7);
  const ulc::Mat3d R_gt = terra::random_rotation(rng);
  const Cloud target = terra_test::scan(R_gt, ulc::Vec3d(0.4, -0.3, 0.1), 32, 1800);

  // Lattice build.
  for (std::size_t n : {1000u, 3000u, 10000u}) {
    terra::Lattice lattice;
    const double s = ulc_bench::median_seconds(repeats, [&] { lattice = terra::Lattice(n); });
    table.add_row({"lattice + cube-map table build", Cell::integer(long(n)), Cell::integer(2),
                   Cell::num(s * 1e3, 2), "", "",
                   "M=" + std::to_string(lattice.grid().cells_per_edge()) + ", " +
                       fmt(lattice.mean_candidates(), 2) + " cand/cell, " +
                       fmt(double(lattice.table_bytes()) / 1e6, 2) + " MB"});
  }

  const terra::Lattice lattice(10000);
  const terra::KdTreeLookup kd(lattice);

  // Descriptor of a 100k-point frame.
  for (int threads : {1, 2}) {
    const double s = in_arena(threads, [&] {
      return ulc_bench::median_seconds(repeats, [&] {
        volatile std::size_t n = terra::make_descriptor(lattice, frame).points_used;
        (void)n;
      });
    });
    table.add_row({"descriptor of a frame", Cell::integer(10000), Cell::integer(threads),
                   Cell::num(s * 1e3, 2), Cell::num(s * 1e9 / double(frame.size()), 1), "ns/point",
                   std::to_string(frame.size()) + " points"});
  }
  {
    const double s = in_arena(1, [&] {
      return ulc_bench::median_seconds(repeats, [&] {
        volatile std::size_t n = terra::make_descriptor(kd, frame).points_used;
        (void)n;
      });
    });
    table.add_row({"descriptor of a frame, kd-tree lookup", Cell::integer(10000), Cell::integer(1),
                   Cell::num(s * 1e3, 2), Cell::num(s * 1e9 / double(frame.size()), 1), "ns/point",
                   std::to_string(frame.size()) + " points"});
  }

  // One rotation evaluation: the fused loop with each lookup.
  const auto f1 = terra::make_descriptor(lattice, base);
  const auto f2 = terra::make_descriptor(lattice, target);
  const terra::DistanceParams dp;
  const auto bc = terra::base_cells(lattice, f1, dp.d1);
  const auto tc = terra::target_cells(f2, dp.d1);
  std::vector<ulc::Mat3d> rotations;
  for (int i = 0; i < 200; ++i) rotations.push_back(terra::random_rotation(rng));
  double fused_per_rotation = 0;
  auto eval_row = [&](const char* name, const auto& lookup, std::size_t count) {
    const double s = in_arena(1, [&] {
      return ulc_bench::median_seconds(repeats, [&] {
        double acc = 0;
        for (std::size_t r = 0; r < count; ++r)
          acc += terra::rotated_distance(bc, tc, lookup, rotations[r], dp).abs_sum;
        volatile double sink = acc;
        (void)sink;
      });
    });
    const double per_rotation = s / double(count);
    table.add_row({name, Cell::integer(10000), Cell::integer(1), Cell::num(per_rotation * 1e3, 4),
                   Cell::num(per_rotation * 1e9 / double(bc.size()), 1), "ns/cell",
                   std::to_string(bc.size()) + " base cells > d1; median_ms per rotation"});
    return per_rotation;
  };
  fused_per_rotation = eval_row("rotation evaluation, O(1) cube map, batched", lattice, 200);
  eval_row("rotation evaluation, O(1) cube map, one by one", OneByOne{lattice}, 200);
  const double kd_per_rotation = eval_row("rotation evaluation, kd-tree (paper)", kd, 20);

  // The naive way: turn the cloud, rebuild, compare.
  for (const Cloud* cloud : {&target, static_cast<const Cloud*>(&frame)}) {
    Cloud scratch;
    const terra::Descriptor<double> fb = terra::make_descriptor(lattice, base);
    for (int threads : {1, 2}) {
      const std::size_t count = 10;
      const double s = in_arena(threads, [&] {
        return ulc_bench::median_seconds(repeats, [&] {
          double acc = 0;
          for (std::size_t r = 0; r < count; ++r)
            acc += naive_distance(lattice, fb, *cloud, rotations[r], scratch);
          volatile double sink = acc;
          (void)sink;
        });
      });
      const double per_rotation = s / double(count);
      table.add_row(
          {"naive: turn cloud + rebuild descriptor", Cell::integer(10000), Cell::integer(threads),
           Cell::num(per_rotation * 1e3, 3), Cell::num(per_rotation / fused_per_rotation, 0),
           "x fused",
           std::to_string(cloud->size()) + " points; median_ms per rotation; fused is 1 thread"});
    }
  }
  table.add_row({"kd-tree (paper) vs O(1) batched", Cell::integer(10000), Cell::integer(1), "",
                 Cell::num(kd_per_rotation / fused_per_rotation, 1), "x slower", ""});

  // The full two-step search on the synthetic pair.
  auto search_rows = [&](const std::string& scene, const Cloud& b, const Cloud& t,
                         const ulc::Mat3d& truth, std::vector<std::size_t> sizes) {
    for (std::size_t n : sizes) {
      const terra::Lattice lat(n);
      for (int threads : {1, 2}) {
        terra::SearchResult last;
        const double s = in_arena(threads, [&] {
          return ulc_bench::median_seconds(repeats,
                                           [&] { last = terra::estimate_rotation(lat, b, t); });
        });
        const auto& st = last.stats;
        const double error = ulc::rotation_error_rad(truth, last.rotation) / kDeg;
        table.add_row(
            {"full search, " + scene, Cell::integer(long(n)), Cell::integer(threads),
             Cell::num(s * 1e3, 1),
             Cell::num(st.seconds() * 1e9 / double(std::max<std::uint64_t>(1, st.cell_evaluations)),
                       1),
             "ns/cell",
             std::string(terra::to_string(last.status)) + ", e_rot " + fmt(error, 2) +
                 " deg; rotations " + std::to_string(st.overlap.rotations) + "/" +
                 std::to_string(st.coarse.rotations) + "/" + std::to_string(st.fine.rotations) +
                 "; base cells > d1 " + std::to_string(st.base_beyond_d1) + "; descriptors " +
                 fmt(st.descriptor_seconds * 1e3, 1) + " ms"});
      }
    }
  };
  search_rows("synthetic crossroads 64/32 beams", base, target, R_gt, {1000, 3000, 10000});

  std::string error;
  const auto sim = simulated_pairs("64-32", 1, 0.5, 1, error);
  if (!sim.empty()) {
    search_rows("simulated 64-32 pair", sim[0].base, sim[0].target, sim[0].R_base_target, {10000});
    Cloud scratch;
    const auto fb = terra::make_descriptor(lattice, sim[0].base);
    const auto fbt = terra::make_descriptor(lattice, sim[0].target);
    const auto sbc = terra::base_cells(lattice, fb, dp.d1);
    const auto stc = terra::target_cells(fbt, dp.d1);
    const double fused =
        in_arena(1,
                 [&] {
                   return ulc_bench::median_seconds(repeats, [&] {
                     double acc = 0;
                     for (const auto& R : rotations)
                       acc += terra::rotated_distance(sbc, stc, lattice, R, dp).abs_sum;
                     volatile double sink = acc;
                     (void)sink;
                   });
                 }) /
        double(rotations.size());
    const double naive =
        in_arena(1,
                 [&] {
                   return ulc_bench::median_seconds(repeats, [&] {
                     double acc = 0;
                     for (std::size_t r = 0; r < 5; ++r)
                       acc += naive_distance(lattice, fb, sim[0].target, rotations[r], scratch);
                     volatile double sink = acc;
                     (void)sink;
                   });
                 }) /
        5.0;
    table.add_row({"simulated 64-32: fused rotation evaluation", Cell::integer(10000),
                   Cell::integer(1), Cell::num(fused * 1e3, 4),
                   Cell::num(fused * 1e9 / double(sbc.size()), 1), "ns/cell",
                   std::to_string(sbc.size()) + " base cells > d1"});
    table.add_row({"simulated 64-32: naive per rotation", Cell::integer(10000), Cell::integer(1),
                   Cell::num(naive * 1e3, 3), Cell::num(naive / fused, 0), "x fused",
                   std::to_string(sim[0].target.size()) + " target points"});
  } else {
    table.add_row({"simulated 64-32", "", "", "", "", "", "skipped: " + error});
  }

  const ulc_bench::Machine m = ulc_bench::machine();
  if (options.json) {
    table.write_json(std::cout, "bench_terra", m, repeats,
                     {{"d1_m", Cell::num(dp.d1, 1)},
                      {"d2_m", Cell::num(dp.d2, 1)},
                      {"alpha", Cell::num(dp.alpha, 1)}});
  } else {
    std::cout << "bench_terra on " << m.cpu << " (" << m.threads << " threads, load " << m.load
              << "), median of " << repeats << "\n\n";
    table.print(std::cout);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------

struct AccuracyOptions {
  std::vector<std::string> pairs = {"64-32"};
  std::size_t samples = 50;
  std::uint64_t seed = 1;
  std::size_t lattice = 10000;
  bool adaptive_d1 = terra::AdaptiveD1().enabled;
  double min_overlap = terra::SearchParams().min_overlap_ratio;
  int threads = 2;
  double spacing_s = 0.2;
  std::size_t top_k = terra::SearchParams().top_k;
  double coarse_stride_deg = terra::SearchParams().coarse_stride_deg;
  terra::DistanceParams distance;
  std::optional<ulc::Vec3d> mount_offset;  ///< --mount-offset (move_target)
  bool fpfh = false;                       ///< --fpfh: the FPFH + RANSAC baseline too
};

/// e_rot (deg) of the FPFH + RANSAC baseline (fpfh_baseline.hpp) on a frame pair; 180 when it
/// finds nothing.
double fpfh_error_deg(const Cloud& base, const Cloud& target, const ulc::Mat3d& truth,
                      std::uint64_t seed, int threads) {
  fpfh_baseline::Options o;
  o.seed = seed;
  return in_arena(threads, [&] {
    const auto r = fpfh_baseline::register_frames(fpfh_baseline::describe(base, o),
                                                  fpfh_baseline::describe(target, o), o);
    return r.ok ? ulc::rotation_error_rad(truth, r.rotation) / kDeg : 180.0;
  });
}

std::string offset_text(const std::optional<ulc::Vec3d>& offset) {
  if (!offset) return "the scenario's";
  std::ostringstream s;
  s << "base + (" << (*offset)[0] << ", " << (*offset)[1] << ", " << (*offset)[2] << ") m";
  return s.str();
}

int run_accuracy(const ulc_bench::Options& options, const AccuracyOptions& acc) {
  ulc_bench::Table table({"pair", "samples", "terra_success_pct", "terra_median_deg",
                          "terra_mean_s", "sc_success_pct", "sc_median_deg", "sc_mean_s",
                          "fpfh_success_pct", "fpfh_median_deg", "fpfh_mean_s", "note"});
  const terra::Lattice lattice(acc.lattice);
  terra::SearchParams params;
  params.adaptive_d1.enabled = acc.adaptive_d1;
  params.min_overlap_ratio = acc.min_overlap;
  params.top_k = acc.top_k;
  params.coarse_stride_deg = acc.coarse_stride_deg;
  params.distance = acc.distance;
  for (const std::string& name : acc.pairs) {
    std::string error;
    const auto pairs =
        simulated_pairs(name, acc.samples, acc.spacing_s, acc.seed, error, acc.mount_offset);
    if (pairs.empty()) {
      table.add_row({name, "0", "", "", "", "", "", "", "", "", "", error});
      continue;
    }
    std::vector<double> te, se, fe;
    double tt = 0, st = 0, ft = 0;
    std::size_t ts = 0, ss = 0, fs = 0, adapted = 0;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const Pair& p = pairs[k];
      const std::uint64_t seed = acc.seed * 1000003u + k;
      const auto c = in_arena(acc.threads, [&] {
        return terra::profile_case(lattice, p.base, p.target, p.R_base_target, seed, params);
      });
      te.push_back(c.error_deg);
      ts += c.error_deg < ulc::kRotationInitMaxRotationDeg;
      tt += c.result.stats.seconds() + c.result.stats.descriptor_seconds;
      adapted += c.result.stats.d1_adapted;
      // scancontext* on the same turned target.
      Cloud turned(p.target.size());
      for (std::size_t i = 0; i < turned.size(); ++i) turned[i] = c.applied * p.target[i];
      const auto t0 = std::chrono::steady_clock::now();
      const auto sc = terra::scan_context_rotation(p.base, turned);
      st += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double e = sc.ok ? ulc::rotation_error_rad(c.truth, sc.rotation) / kDeg : 180.0;
      se.push_back(e);
      ss += e < ulc::kRotationInitMaxRotationDeg;
      std::string fpfh_text;
      if (acc.fpfh) {
        const auto t1 = std::chrono::steady_clock::now();
        const double f = fpfh_error_deg(p.base, turned, c.truth, seed, acc.threads);
        ft += std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
        fe.push_back(f);
        fs += f < ulc::kRotationInitMaxRotationDeg;
        fpfh_text = ", fpfh " + fmt(f, 2) + " deg";
      }
      if (!options.json)
        std::cerr << name << " sample " << k << ": terra " << fmt(c.error_deg, 2) << " deg (d1 "
                  << fmt(c.result.stats.d1_used, 1) << "), scancontext* " << fmt(e, 2) << " deg"
                  << fpfh_text << "\n";
    }
    const double n = double(pairs.size());
    table.add_row({name, Cell::integer(long(pairs.size())), Cell::num(100.0 * double(ts) / n, 1),
                   Cell::num(median(te), 2), Cell::num(tt / n, 3),
                   Cell::num(100.0 * double(ss) / n, 1), Cell::num(median(se), 2),
                   Cell::num(st / n, 3), acc.fpfh ? Cell::num(100.0 * double(fs) / n, 1) : "",
                   acc.fpfh ? Cell::num(median(fe), 2) : "", acc.fpfh ? Cell::num(ft / n, 3) : "",
                   error.empty() ? "d1 adapted in " + std::to_string(adapted) : error});
  }
  const ulc_bench::Machine m = ulc_bench::machine();
  if (options.json) {
    table.write_json(std::cout, "bench_terra_accuracy", m, 1,
                     {{"lattice", Cell::integer(long(acc.lattice))},
                      {"seed", Cell::integer(long(acc.seed))},
                      {"adaptive_d1", acc.adaptive_d1 ? "on" : "off"},
                      {"min_overlap_ratio", Cell::num(acc.min_overlap, 2)},
                      {"top_k", Cell::integer(long(acc.top_k))},
                      {"coarse_stride_deg", Cell::num(acc.coarse_stride_deg, 1)},
                      {"d1_m", Cell::num(acc.distance.d1, 1)},
                      {"d2_m", Cell::num(acc.distance.d2, 1)},
                      {"alpha", Cell::num(acc.distance.alpha, 2)},
                      {"threads", Cell::integer(acc.threads)},
                      {"mount_offset_m", offset_text(acc.mount_offset)},
                      {"success", "e_rot < 10 deg"}});
  } else {
    std::cout << "bench_terra --accuracy: target turned by a uniform random rotation per sample;"
              << " success = e_rot < 10 deg; N = " << acc.lattice << ", adaptive d1 "
              << (acc.adaptive_d1 ? "on" : "off") << ", min overlap ratio " << acc.min_overlap
              << "\n\n";
    table.print(std::cout);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------

struct LandscapeOptions {
  std::vector<std::string> pairs = {"64-32", "64-tele"};
  std::size_t samples = 5;
  double spacing_s = 2.0;  ///< seconds between the frame pairs along the drive
  double step_deg = 10.0;
  std::string png;  ///< folder for the pictures; empty: none
};

/// One row per pair and distance (terra_landscape.hpp).
int run_landscape(const ulc_bench::Options& options, const AccuracyOptions& acc,
                  const LandscapeOptions& lo) {
  namespace tl = terra_landscape;
  ulc_bench::Table table({"pair", "distance", "samples", "truth_cell_deg", "minimum_median_deg",
                          "minimum_within_15deg_pct", "truth_rank_median", "note"});
  const terra::Lattice lattice(acc.lattice);
  const tl::Grid grid(lo.step_deg);
  const terra::SearchParams search;
  for (const std::string& name : lo.pairs) {
    std::string error;
    const auto pairs = simulated_pairs(name, lo.samples, lo.spacing_s, acc.seed, error);
    const char* names[3] = {"eq:feature_dis", "eq:feature_dis, overlap rule", "ED"};
    const char* files[3] = {"feature_dis", "overlap_rule", "ed"};
    std::vector<double> truth_cell, minimum[3], rank[3];
    std::size_t within[3] = {0, 0, 0};
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const Pair& p = pairs[k];
      const auto f1 = terra::make_descriptor(lattice, p.base, search.descriptor);
      const auto f2 = terra::make_descriptor(lattice, p.target, search.descriptor);
      const auto land = in_arena(acc.threads, [&] {
        return tl::evaluate(lattice, f1, f2, acc.distance, grid, p.R_base_target);
      });
      double angle = 0.0, ruled_truth = 0.0;
      const std::size_t cell = tl::nearest_cell(grid, p.R_base_target, angle);
      truth_cell.push_back(angle);
      const std::vector<double> ruled = tl::with_overlap_rule(land, acc.min_overlap, ruled_truth);
      const std::vector<double>* d[3] = {&land.feature, &ruled, &land.euclidean};
      const double at_truth[3] = {land.truth_feature, ruled_truth, land.truth_euclidean};
      for (int m = 0; m < 3; ++m) {
        const tl::Verdict v = tl::judge(grid, *d[m], at_truth[m], p.R_base_target);
        minimum[m].push_back(v.minimum_error_deg);
        rank[m].push_back(static_cast<double>(v.truth_rank));
        within[m] += v.minimum_error_deg < 15.0;
        if (k == 0 && !lo.png.empty()) {
          const std::string path = lo.png + "/terra_landscape_" + name + "_" + files[m] + ".png";
          if (!tl::write_slice_png(path, grid, *d[m], cell))
            std::cerr << "bench_terra: could not write " << path << "\n";
        }
      }
      if (!options.json)
        std::cerr << name << " pair " << k << ": grid minimum " << fmt(minimum[0].back(), 1)
                  << " / " << fmt(minimum[1].back(), 1) << " / " << fmt(minimum[2].back(), 1)
                  << " deg from the truth, the truth's rank " << rank[0].back() << " / "
                  << rank[1].back() << " / " << rank[2].back() << " (" << names[0] << " / "
                  << names[1] << " / " << names[2] << ")\n";
    }
    for (int m = 0; m < 3; ++m) {
      const double n = static_cast<double>(pairs.size());
      table.add_row({name, names[m], Cell::integer(long(pairs.size())),
                     Cell::num(median(truth_cell), 1), Cell::num(median(minimum[m]), 1),
                     Cell::num(n > 0 ? 100.0 * double(within[m]) / n : 0.0, 1),
                     Cell::num(median(rank[m]), 0), error});
    }
  }
  const ulc_bench::Machine m = ulc_bench::machine();
  if (options.json) {
    table.write_json(std::cout, "bench_terra_landscape", m, 1,
                     {{"lattice", Cell::integer(long(acc.lattice))},
                      {"seed", Cell::integer(long(acc.seed))},
                      {"grid_step_deg", Cell::num(lo.step_deg, 1)},
                      {"grid_rotations", Cell::integer(long(grid.size()))},
                      {"min_overlap_ratio", Cell::num(acc.min_overlap, 2)}});
  } else {
    std::cout << "bench_terra --landscape: " << grid.size() << " rotations every " << lo.step_deg
              << " deg (Euler ZYX); N = " << acc.lattice << ", d1 " << acc.distance.d1 << " m, d2 "
              << acc.distance.d2 << " m, alpha " << acc.distance.alpha << "\n\n";
    table.print(std::cout);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// --maps: TERRA on frames vs on local maps (pipeline/map_terra.hpp) vs the automatic choice,
// each through ulc::calibrate_pair with the terra stage alone.

struct MapsOptions {
  std::vector<std::string> pairs = {"64-tele",  "horizon-tele", "16-tele",
                                    "32-mid40", "pitched-90",   "64-32"};
  std::size_t starts = 8;  ///< start frames along the drive
  double spacing_s = 3.0;  ///< between starts
  double window_s = ulc::MapTerraOptions().window_s;
  std::uint64_t seed = 1;
  unsigned decimation = 1;
  int threads = 2;
  std::size_t below_mask = ulc::CalibrateOptions().tuning.terra_source.maps_below_mask;
  std::vector<ulc::TerraSource> sources = {ulc::TerraSource::frames, ulc::TerraSource::maps,
                                           ulc::TerraSource::automatic};
  bool motion = true;  ///< the motion frame on (MapTerraOptions::motion)
  std::size_t vote_frames = ulc::MotionFrameOptions().vote_frames;  ///< frames the vote uses
  std::size_t unsure_vote_frames = ulc::MotionFrameOptions().unsure_vote_frames;
  bool scan_context = false;  ///< a scancontext* row on each window's first frames
};

/// One start: the window's frames of each LiDAR from the start on (target turned by Q).
struct Window {
  std::vector<ulc::PointCloud<float>> base, target;
  std::vector<double> base_times, target_times;
  ulc::Mat3d truth = ulc::Mat3d::Identity();  ///< R_base_target of the turned target
};

/// `starts` windows of `window_s` seconds, `spacing_s` apart along a simulated drive of the
/// scenario's first pair; each window's target turned by a rotation uniform on SO(3) (seeded).
std::vector<Window> simulated_windows(const std::string& name, const MapsOptions& mo,
                                      std::string& error) {
  std::vector<Window> out;
  const auto fp = first_pair(name, error);
  if (!fp) return out;
  const std::size_t bi = fp->base, ti = fp->target;
  ulc::sim::SimulationOptions so;
  so.seed = mo.seed;
  so.decimation = mo.decimation;
  so.keep_frames = false;
  const double first_s = 1.0;  // skip the first second (the drive starts from rest)
  so.seconds = first_s + mo.spacing_s * double(mo.starts) + mo.window_s + 0.5;
  // Keep only frames inside some window (by their own timestamps; clocks agree but for the
  // pair's offset, handled below by pairing the target start in time).
  auto in_window = [&](double t) {
    for (std::size_t s = 0; s < mo.starts; ++s) {
      const double t0 = first_s + mo.spacing_s * double(s);
      if (t >= t0 - 0.2 && t <= t0 + mo.window_s + 0.2) return true;
    }
    return false;
  };
  std::map<std::size_t, ulc::PointCloud<float>> base_frames, target_frames;
  const auto sink = [&](const ulc::sim::FrameEvent& e) {
    if (e.lidar == bi && in_window(e.timestamp)) base_frames[e.frame] = e.cloud;
    if (e.lidar == ti && in_window(e.timestamp)) target_frames[e.frame] = e.cloud;
    return true;
  };
  const auto result = ulc::sim::simulate(fp->spec, so, sink);
  const ulc::sim::PairTruth* truth = simulated_truth(result, fp->pair, name, error);
  if (!truth) return out;
  const auto& ds = result.dataset;
  const auto& bt = ds.lidars[bi].timestamps;
  const auto& tt = ds.lidars[ti].timestamps;
  for (std::size_t s = 0; s < mo.starts; ++s) {
    const double t0 = first_s + mo.spacing_s * double(s);
    // Base start: first frame at or after t0; target start: nearest to it in time.
    std::size_t kb = 0;
    while (kb < bt.size() && bt[kb] < t0) ++kb;
    if (kb == bt.size()) break;
    std::size_t kt = 0;
    double best = 1e9;
    for (std::size_t j = 0; j < tt.size(); ++j) {
      const double dt = std::fabs(tt[j] + truth->time_offset_s - bt[kb]);
      if (dt < best) best = dt, kt = j;
    }
    terra::SplitMix64 rng(mo.seed * 1000003u + s);
    const ulc::Mat3d Q = terra::random_rotation(rng);
    const ulc::Mat3<float> Qf = Q.cast<float>();
    Window w;
    w.truth = truth->T_base_target.linear() * Q.transpose();
    for (std::size_t k = kb; k < bt.size() && bt[k] <= bt[kb] + mo.window_s + 1e-6; ++k) {
      const auto it = base_frames.find(k);
      if (it == base_frames.end()) break;
      w.base.push_back(it->second);
      w.base_times.push_back(bt[k]);
    }
    for (std::size_t k = kt; k < tt.size() && tt[k] <= tt[kt] + mo.window_s + 1e-6; ++k) {
      const auto it = target_frames.find(k);
      if (it == target_frames.end()) break;
      ulc::PointCloud<float> turned = it->second;
      for (auto& p : turned.points) p = Qf * p;
      w.target.push_back(std::move(turned));
      w.target_times.push_back(tt[k]);
    }
    if (w.base.empty() || w.target.empty()) continue;
    out.push_back(std::move(w));
  }
  if (out.size() < mo.starts) error = name + ": only " + std::to_string(out.size()) + " windows";
  return out;
}

/// One source's outcome over the windows of a pair.
struct SourceTally {
  std::vector<double> errors, masks;
  double seconds = 0.0;
  std::size_t ok5 = 0, ok10 = 0, chose_maps = 0, motion_used = 0, motion_ok = 0;

  void add(double error_deg, double mask, double s) {
    errors.push_back(error_deg);
    masks.push_back(mask);
    ok5 += error_deg < 5.0;
    ok10 += error_deg < ulc::kRotationInitMaxRotationDeg;
    seconds += s;
  }
};

/// The terra stage alone on one window with `source`.
ulc::PairCalibration terra_on_window(const Window& w, ulc::TerraSource source,
                                     const MapsOptions& mo) {
  ulc::CalibrateOptions co;
  co.stages = {ulc::Stage::terra};
  co.tuning.terra_source.source = source;
  co.tuning.terra_source.maps.window_s = mo.window_s;
  co.tuning.terra_source.maps.motion.enabled = mo.motion;
  co.tuning.terra_source.maps.motion.vote_frames = mo.vote_frames;
  co.tuning.terra_source.maps.motion.unsure_vote_frames = mo.unsure_vote_frames;
  co.tuning.terra_source.maps_below_mask = mo.below_mask;
  return in_arena(mo.threads, [&] {
    return ulc::calibrate_pair(w.base, w.base_times, w.target, w.target_times, co);
  });
}

void log_window(const std::string& name, std::size_t k, const char* label, double err,
                const ulc::PairCalibration& r) {
  const auto& t = r.terra;
  std::cerr << name << " start " << k << " " << label << ": e_rot " << fmt(err, 2) << " deg, mask "
            << (t ? t->mask_count : 0) << ", source "
            << (t ? std::string(ulc::to_string(t->source)) : std::string("-")) << ", motion "
            << (t && t->motion
                    ? (t->motion->ok ? (t->motion->used ? "used" : "agrees") : t->motion->reason)
                    : std::string("-"));
  if (t && t->motion && t->motion->ok) std::cerr << " (" << t->motion->method << ")";
  if (t && t->motion && t->motion->vote_ran)
    std::cerr << ", vote " << t->motion->votes_confident << "/" << t->motion->votes
              << " sure, score " << fmt(t->motion->vote.score, 2) << ", margin "
              << fmt(t->motion->vote.margin, 2) << ", voxels " << t->motion->vote.points;
  std::cerr << ", " << fmt(r.timing_s.terra, 2) << " s\n";
}

SourceTally run_source(const std::string& name, const std::vector<Window>& windows,
                       ulc::TerraSource source, const char* label, const MapsOptions& mo,
                       bool log) {
  SourceTally tally;
  for (std::size_t k = 0; k < windows.size(); ++k) {
    const Window& w = windows[k];
    const ulc::PairCalibration r = terra_on_window(w, source, mo);
    const double e = r.terra ? ulc::rotation_error_rad(w.truth, r.terra->rotation) / kDeg : 180.0;
    const double err = r.success ? e : 180.0;
    tally.add(err, r.terra ? double(r.terra->mask_count) : 0.0, r.timing_s.terra);
    tally.chose_maps += r.terra && r.terra->source == ulc::TerraSource::maps;
    tally.motion_ok += r.terra && r.terra->motion && r.terra->motion->ok;
    tally.motion_used += r.terra && r.terra->motion && r.terra->motion->used;
    if (log) log_window(name, k, label, err, r);
  }
  return tally;
}

/// scancontext* on each window's first frame pair (the target's frame turned as the window's).
SourceTally run_scan_context(const std::vector<Window>& windows) {
  SourceTally tally;
  for (const Window& w : windows) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto sc = terra::scan_context_rotation(w.base.front(), w.target.front());
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    tally.add(sc.ok ? ulc::rotation_error_rad(w.truth, sc.rotation) / kDeg : 180.0, 0.0, s);
  }
  return tally;
}

std::string source_note(ulc::TerraSource source, const SourceTally& t, std::size_t n,
                        const std::string& error) {
  std::string note;
  if (source == ulc::TerraSource::automatic)
    note = "maps chosen " + std::to_string(t.chose_maps) + "/" + std::to_string(n);
  if (source != ulc::TerraSource::frames)
    note += std::string(note.empty() ? "" : "; ") + "motion ok " + std::to_string(t.motion_ok) +
            ", used " + std::to_string(t.motion_used);
  if (!error.empty()) note += (note.empty() ? "" : "; ") + error;
  return note;
}

void add_tally_row(ulc_bench::Table& table, const std::string& name, const char* label,
                   const SourceTally& t, const std::string& note) {
  const double n = double(t.errors.size());
  table.add_row({name, label, Cell::integer(long(t.errors.size())),
                 Cell::num(100.0 * double(t.ok5) / n, 1), Cell::num(100.0 * double(t.ok10) / n, 1),
                 Cell::num(median(t.errors), 2), Cell::num(median(t.masks), 0),
                 Cell::num(t.seconds / n, 2), note});
}

int run_maps(const ulc_bench::Options& options, const MapsOptions& mo) {
  ulc_bench::Table table({"pair", "source", "starts", "success_5deg_pct", "success_10deg_pct",
                          "median_deg", "median_mask", "mean_s", "note"});
  for (const std::string& name : mo.pairs) {
    std::string error;
    const auto windows = simulated_windows(name, mo, error);
    if (windows.empty()) {
      table.add_row({name, "", "0", "", "", "", "", "", error});
      continue;
    }
    for (const ulc::TerraSource source : mo.sources) {
      const char* label = ulc::to_string(source);
      const SourceTally t = run_source(name, windows, source, label, mo, !options.json);
      add_tally_row(table, name, label, t, source_note(source, t, windows.size(), error));
    }
    if (mo.scan_context)
      add_tally_row(table, name, "scancontext*", run_scan_context(windows), "first frames");
  }
  const ulc_bench::Machine m = ulc_bench::machine();
  if (options.json) {
    table.write_json(std::cout, "bench_terra_maps", m, 1,
                     {{"seed", Cell::integer(long(mo.seed))},
                      {"starts", Cell::integer(long(mo.starts))},
                      {"spacing_s", Cell::num(mo.spacing_s, 2)},
                      {"window_s", Cell::num(mo.window_s, 2)},
                      {"decimation", Cell::integer(long(mo.decimation))},
                      {"below_mask", Cell::integer(long(mo.below_mask))},
                      {"motion_frame", mo.motion ? "on" : "off"},
                      {"threads", Cell::integer(mo.threads)},
                      {"success", "e_rot < 5 deg (and < 10 deg)"}});
  } else {
    std::cout << "bench_terra --maps: " << mo.starts << " starts " << mo.spacing_s
              << " s apart, window " << mo.window_s << " s, target turned by a uniform random "
              << "rotation per start; motion frame " << (mo.motion ? "on" : "off")
              << "; a failed search counts as 180 deg\n\n";
    table.print(std::cout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  bool accuracy = false, maps = false, windows = false;
  AccuracyOptions acc;
  MapsOptions mo;
  CLI::App app(
      "TERRA speed (default), accuracy against scancontext* (--accuracy) or frames vs "
      "local maps (--maps); see the top of bench/bench_terra.cpp",
      "bench_terra");
  ulc_bench::Options options;
  ulc_bench::add_options(app, options);
  app.add_flag("--accuracy", accuracy, "TERRA against scancontext* on simulated rig pairs");
  app.add_flag("--fpfh", acc.fpfh, "--accuracy: the FPFH + RANSAC baseline too");
  bool landscape = false;
  LandscapeOptions lo;
  app.add_flag("--landscape", landscape,
               "eq:feature_dis against the Euclidean distance over a grid of rotations");
  app.add_option("--grid-step", lo.step_deg, "--landscape: grid step in degrees (default 10)")
      ->type_name("DEG")
      ->check(CLI::Range(2.0, 90.0));
  app.add_option("--png", lo.png, "--landscape: folder for the slice pictures")->type_name("DIR");
  app.add_flag("--maps", maps, "TERRA on frames against local maps");
  app.add_flag("--windows", windows,
               "issue 34's protocol: the eight paper pairs, 50 windows of 2 s, 1 s apart; frames, "
               "automatic and scancontext*");
  app.add_flag_callback(
      "--no-motion", [&] { mo.motion = false; }, "--maps/--windows: the motion frame off");
  app.add_option("--vote-frames", mo.vote_frames,
                 "--maps/--windows: target frames the ground vote uses (default 3)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  app.add_option("--unsure-vote-frames", mo.unsure_vote_frames,
                 "--maps/--windows: frames the vote uses where none of the first is sure "
                 "(default 5; 0: none)")
      ->type_name("N");
  app.add_option("--starts", mo.starts, "--maps: windows per pair (default 8)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  app.add_option("--spacing", mo.spacing_s, "--maps: seconds between windows (default 3)")
      ->type_name("S");
  app.add_option("--window", mo.window_s,
                 "--maps: seconds per window (default: the pipeline's, 5; --windows: 2)")
      ->type_name("S");
  app.add_option("--decimation", mo.decimation, "--maps: keep every Nth point (default 1)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  app.add_option("--below-mask", mo.below_mask,
                 "--maps: local maps when the frame search overlaps in fewer cells (default 100)")
      ->type_name("N");
  auto* pairs_option = app.add_option("--pairs", acc.pairs, "pair scenarios (default: the mode's)")
                           ->delimiter(',')
                           ->type_name("A,B,...");
  app.add_option("--samples", acc.samples, "--accuracy: frame pairs per scenario (default 50)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  app.add_option("--seed", acc.seed, "seed (default 1)")->type_name("N");
  app.add_option("--lattice", acc.lattice, "--accuracy: rotations of the lattice (default 10000)")
      ->type_name("N")
      ->check(CLI::Range(std::size_t{2}, std::numeric_limits<std::size_t>::max()));
  app.add_flag_callback(
      "--adaptive-d1", [&] { acc.adaptive_d1 = true; }, "--accuracy: adapt d1 (default)");
  app.add_flag_callback(
      "--no-adaptive-d1", [&] { acc.adaptive_d1 = false; }, "--accuracy: keep d1 fixed");
  app.add_option("--min-overlap", acc.min_overlap,
                 "--accuracy: minimum overlap ratio (default 0.2)")
      ->type_name("X");
  app.add_option("--top-k", acc.top_k, "--accuracy: hypotheses kept (default 10)")
      ->type_name("K")
      ->check(CLI::PositiveNumber);
  app.add_option("--d1", acc.distance.d1, "--accuracy: distance d1 (default 20)")->type_name("X");
  app.add_option("--d2", acc.distance.d2, "--accuracy: distance d2 (default 5)")->type_name("X");
  app.add_option("--alpha", acc.distance.alpha, "--accuracy: distance alpha (default 2)")
      ->type_name("X");
  app.add_option("--coarse-stride", acc.coarse_stride_deg,
                 "--accuracy: coarse stride in degrees (default 10)")
      ->type_name("DEG");
  std::vector<double> mount_offset;
  app.add_option("--mount-offset", mount_offset,
                 "--accuracy: the target at the base's position plus this offset (m, vehicle "
                 "frame: x forward, y left)")
      ->delimiter(',')
      ->expected(3)
      ->type_name("X,Y,Z");
  ulc_bench::add_threads_option(app, acc.threads);
  CLI11_PARSE(app, argc, argv);
  if (mount_offset.size() == 3)
    acc.mount_offset = ulc::Vec3d(mount_offset[0], mount_offset[1], mount_offset[2]);
  const bool pairs_given = pairs_option->count() > 0;
  if (windows) {
    mo.pairs = {"64-32",   "32-16",        "64-horizon", "32-avia",
                "64-tele", "horizon-tele", "16-tele",    "32-mid40"};
    if (app.count("--starts") == 0) mo.starts = 50;
    if (app.count("--spacing") == 0) mo.spacing_s = 1.0;
    if (app.count("--window") == 0) mo.window_s = 2.0;
    mo.sources = {ulc::TerraSource::frames, ulc::TerraSource::automatic};
    mo.scan_context = true;
  }
  if (maps || windows) {
    if (pairs_given) mo.pairs = acc.pairs;
    mo.seed = acc.seed;
    mo.threads = acc.threads;
    return run_maps(options, mo);
  }
  if (landscape) {
    if (pairs_given) lo.pairs = acc.pairs;
    if (app.count("--samples") > 0) lo.samples = acc.samples;
    return run_landscape(options, acc, lo);
  }
  return accuracy ? run_accuracy(options, acc) : run_speed(options);
}
