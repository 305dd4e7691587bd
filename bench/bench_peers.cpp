// bench_peers: our point-to-plane ICP against PCL's and Open3D's on the same clouds.
//
//   bench_peers [--seed 3] [--disturbances 5] [--threads 2] [--repeats 5] [--json]
//
// The clouds: one frame of each LiDAR of the 64-32 rig, the vehicle parked (no motion
// distortion, so the ground truth is the answer every method should reach). Target: the
// HDL-64E frame at 0.2 m voxels; source: the VLP-32C frame at 0.25, 0.5 and 1.0 m. Starts: the
// truth disturbed by 2 deg about a random axis and 0.3 m in a random direction, seeded.
//
// Two rows per method and source voxel:
//   - "ICP": the registration alone, every method with the same target points and normals
//     (ours, from ulc::PlaneCloud), the same gate (1 m) and the same cap (30 correspondence
//     searches). Ours is timed with its target prepared (kd-tree and normals built once, as
//     JEEP and HOTS use it); PCL and Open3D build their target kd-tree inside their ICP call,
//     which is how their API works: that build is timed separately in the "kd-tree" rows.
//   - "normals + ICP": each library's whole job from the raw clouds: its own normals
//     (k = 10), its own search structure, the ICP.
// speed_ratio = the method's median time / ours (same row kind, same threads): > 1 means
// we are faster. Errors are against the simulator's extrinsic: median and worst over the
// disturbances.
//
// Peers are compiled in only when CMake finds them (Debian: libpcl-dev, libopen3d-dev); the
// bench builds and runs ours alone without them, and says which peers are missing.
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "../tests/jeep/jeep_test_util.hpp"
#include "peers/peer_icp.hpp"
#include "support/bench_util.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/registration_target.hpp"
#include "ulc/core/voxel_downsample.hpp"
#include "ulc/sim/simulate.hpp"

namespace {

using Cell = ulc_bench::Cell;
using ulc::Isometry3d;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct Config {
  std::uint64_t seed = 3;
  std::size_t disturbances = 5;
  int threads = 2;
  ulc_bench::Options bench;
};

/// One frame per LiDAR of the parked 64-32 rig and its extrinsic.
struct ParkedPair {
  ulc::PointCloud<float> target, source;  ///< HDL-64E, VLP-32C
  Isometry3d truth = Isometry3d::Identity();
};

ParkedPair parked_pair(std::uint64_t seed) {
  ulc::sim::SimulationOptions o;
  o.seconds = 0.2;
  o.seed = seed;
  o.static_at_s = 6.0;
  const auto data = ulc::sim::simulate(*ulc::sim::scenario("64-32"), o).dataset;
  ParkedPair p;
  p.target = data.lidars.at(0).frames.at(0);
  p.source = data.lidars.at(1).frames.at(0);
  p.truth = data.pairs.at(0).T_base_target;
  return p;
}

template <class Points>
std::vector<Eigen::Vector3d> to_double(const Points& points) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(p.template cast<double>());
  return out;
}

/// Per method and row kind: times (median over repeats, per start) and errors (per start).
struct Runs {
  std::vector<double> seconds, e_rot_deg, e_trans_cm, iterations;
  void add(double s, const ulc::PoseError& e, int iterations_used) {
    seconds.push_back(s);
    e_rot_deg.push_back(e.rotation_deg);
    e_trans_cm.push_back(100.0 * e.translation_m);
    if (iterations_used >= 0) iterations.push_back(iterations_used);
  }
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return ulc_bench::median_of_sorted(v);
}

double worst(const std::vector<double>& v) {
  return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
}

void add_row(ulc_bench::Table& table, const std::string& method, const std::string& kind,
             double voxel, int threads, std::size_t points, const Runs& r, double ours_s) {
  const double t = median(r.seconds);
  table.add_row({method, kind, Cell::num(voxel, 2), Cell::integer(threads),
                 Cell::integer(static_cast<long long>(points)), Cell::num(1e3 * t, 2),
                 Cell::num(ours_s > 0 ? t / ours_s : 1.0, 2),
                 r.iterations.empty() ? Cell{"-"} : Cell::num(median(r.iterations), 0),
                 Cell::num(median(r.e_rot_deg), 4), Cell::num(worst(r.e_rot_deg), 4),
                 Cell::num(median(r.e_trans_cm), 2), Cell::num(worst(r.e_trans_cm), 2)});
}

void run(const Config& c) {
  std::cerr << "bench_peers: simulating the parked 64-32 rig (seed " << c.seed << ")\n";
  const ParkedPair pair = parked_pair(c.seed);
  const auto target_cloud = ulc::voxel_downsample(pair.target, 0.2).cloud;
  std::vector<Isometry3d> starts;
  std::mt19937_64 rng(c.seed * 1000003ULL + 17);
  for (std::size_t i = 0; i < c.disturbances; ++i)
    starts.push_back(jeep_test::disturbed(pair.truth, rng, 2.0 * kDeg, 0.3));

  ulc_peers::IcpSettings settings;
  ulc::RegistrationOptions ours;  // the defaults: gate 1 m, Geman-McClure 0.1 m, 30 searches
  settings.gate = ours.max_correspondence_distance;
  settings.max_iterations = ours.max_iterations;
  settings.kernel_scale = ours.kernel.scale;
  settings.translation_tolerance = ours.translation_tolerance;
  settings.rotation_tolerance = ours.rotation_tolerance;
  const ulc::PlaneCloud<float> target(target_cloud);
  const auto target_points = to_double(target.points());
  const auto target_normals = to_double(target.normals());
  auto peers = ulc_peers::available_peers();

  ulc_bench::Table table({"method", "rows", "source_voxel_m", "threads", "source_points",
                          "median_ms", "speed_ratio", "iterations", "median_e_rot_deg",
                          "worst_e_rot_deg", "median_e_trans_cm", "worst_e_trans_cm"});
  const std::vector<int> thread_counts =
      c.threads > 1 ? std::vector<int>{1, c.threads} : std::vector<int>{1};
  for (double voxel : {0.25, 0.5, 1.0}) {
    const auto source = ulc::voxel_downsample(pair.source, voxel).cloud;
    const auto source_points = to_double(source.points);
    for (auto& peer : peers)
      peer->set_clouds(source_points, target_points, target_normals, settings);
    for (int threads : thread_counts) {
      tbb::task_arena arena(threads);
      Runs icp, whole;
      for (const auto& start : starts) {
        ulc::RegistrationResult<double> r;
        const double t = ulc_bench::median_seconds(c.bench.repeats, [&] {
          r = arena.execute(
              [&] { return ulc::register_point_to_plane(source, target, start, ours); });
        });
        icp.add(t, ulc::pose_error(pair.truth, r.pose), r.iterations);
        const double tw = ulc_bench::median_seconds(c.bench.repeats, [&] {
          r = arena.execute([&] {
            const ulc::PlaneCloud<float> own(target_cloud);
            return ulc::register_point_to_plane(source, own, start, ours);
          });
        });
        whole.add(tw, ulc::pose_error(pair.truth, r.pose), r.iterations);
      }
      const double ours_icp = median(icp.seconds), ours_whole = median(whole.seconds);
      add_row(table, "ulc", "ICP", voxel, threads, source.size(), icp, ours_icp);
      add_row(table, "ulc", "normals + ICP", voxel, threads, source.size(), whole, ours_whole);
      for (auto& peer : peers) {
        peer->set_threads(threads);
        Runs p_icp, p_whole;
        for (const auto& start : starts) {
          ulc_peers::IcpOutcome o;
          const double t =
              ulc_bench::median_seconds(c.bench.repeats, [&] { o = peer->align(start); });
          p_icp.add(t, ulc::pose_error(pair.truth, o.pose), o.iterations);
          const double tw = ulc_bench::median_seconds(c.bench.repeats,
                                                      [&] { o = peer->normals_and_align(start); });
          p_whole.add(tw, ulc::pose_error(pair.truth, o.pose), o.iterations);
        }
        add_row(table, peer->name(), "ICP", voxel, threads, source.size(), p_icp, ours_icp);
        add_row(table, peer->name(), "normals + ICP", voxel, threads, source.size(), p_whole,
                ours_whole);
      }
    }
  }
  std::vector<std::pair<std::string, Cell>> notes = {
      {"ulc",
       "register_point_to_plane, Geman-McClure 0.1 m, up to 10 Gauss-Newton steps per search"},
      {"speed_ratio", "median time / ulc's (same rows, same threads); > 1: ulc is faster"}};
  for (const auto& peer : peers) notes.emplace_back(peer->name(), peer->method());
  const std::string missing = ulc_peers::missing_peers();
  if (!missing.empty()) notes.emplace_back("not built in", missing + ": install, re-run cmake");
  ulc_bench::emit(std::cout, table, c.bench.json, "bench_peers", c.bench.repeats,
                  {{"scenario", "64-32 parked"},
                   {"seed", Cell::integer(static_cast<long long>(c.seed))},
                   {"target", "HDL-64E frame at 0.2 m, " + std::to_string(target.size()) +
                                  " points with normals"},
                   {"gate_m", Cell::num(settings.gate, 1)},
                   {"max_iterations", Cell::integer(settings.max_iterations)},
                   {"disturbance", "2 deg about a random axis, 0.3 m in a random direction"},
                   {"disturbances", Cell::integer(static_cast<long long>(c.disturbances))}},
                  notes);
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app("point-to-plane ICP: ulc against PCL and Open3D (when built in) on the same clouds",
               "bench_peers");
  ulc_bench::add_options(app, c.bench);
  app.add_option("--seed", c.seed, "disturbance seed (default 3)")->type_name("N");
  app.add_option("--disturbances", c.disturbances, "disturbed starts (default 5)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  ulc_bench::add_threads_option(app, c.threads);
  CLI11_PARSE(app, argc, argv);
  run(c);
  return 0;
}
