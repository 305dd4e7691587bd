// `ulc simulate`: writes a dataset folder (docs/design.md) for a named rig and scene, with exact
// ground truth, and optionally a top-down preview of every LiDAR's first frame.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "command_line.hpp"
#include "commands.hpp"
#include "progress.hpp"
#include "top_down_image.hpp"
#include "ulc/io/pcd.hpp"
#include "ulc/sim/dataset_writer.hpp"
#include "ulc/sim/scenario.hpp"
#include "ulc/sim/simulate.hpp"
#include "usage_error.hpp"

namespace ulc::app {
namespace {

/// First frame of every LiDAR in the vehicle frame (ground truth), top-down and from the side.
void write_preview(const std::string& png, const std::filesystem::path& dir,
                   const sim::Dataset& dataset) {
  constexpr int kWidth = 1000, kTopHeight = 1000, kSideHeight = 260, kLegendRow = 26;
  const int legend_rows = static_cast<int>((dataset.lidars.size() + 3) / 4);
  const int kLegend = 10 + kLegendRow * legend_rows;
  Image image(kWidth, kTopHeight + kSideHeight + kLegend, {18, 18, 22});
  const std::array<int, 4> top{0, 0, kWidth, kTopHeight};
  const std::array<int, 4> side{0, kTopHeight, kWidth, kSideHeight};
  View top_view{0, 1, Eigen::Vector2d(0, 0), 0.08};
  View side_view{0, 2, Eigen::Vector2d(0, 3.0), 0.08};
  for (std::size_t i = 0; i < dataset.lidars.size(); ++i) {
    const auto& lidar = dataset.lidars[i];
    const auto frame = dir / lidar.name / sim::frame_file_name(0);
    const auto cloud = io::read_pcd<std::vector<Eigen::Vector3f>>(frame);
    std::vector<Eigen::Vector3f> in_vehicle;
    in_vehicle.reserve(cloud.size());
    const Eigen::Isometry3f T = lidar.T_vehicle_lidar.cast<float>();
    for (const auto& p : cloud) in_vehicle.push_back(T * p);
    draw_points(image, top, top_view, in_vehicle, palette(i), 0.5f);
    draw_points(image, side, side_view, in_vehicle, palette(i), 0.35f);
    const Eigen::Vector3f origin = T.translation();
    for (const auto* area : {&top, &side}) {
      const View& v = area == &top ? top_view : side_view;
      const int px =
          (*area)[0] + kWidth / 2 +
          static_cast<int>((origin[v.horizontal_axis] - v.centre.x()) / v.metres_per_pixel);
      const int py =
          (*area)[1] + (*area)[3] / 2 -
          static_cast<int>((origin[v.vertical_axis] - v.centre.y()) / v.metres_per_pixel);
      image.fill_rect(px - 3, py - 3, px + 4, py + 4, palette(i));
    }
    // Four entries per legend row.
    const int legend_y = kTopHeight + kSideHeight + 8 + kLegendRow * static_cast<int>(i / 4);
    const int legend_x = 10 + 250 * static_cast<int>(i % 4);
    image.fill_rect(legend_x, legend_y, legend_x + 16, legend_y + 16, palette(i));
    const std::string label = lidar.name + " (" + lidar.model + ")";
    image.text(legend_x + 22, legend_y + 2, label.substr(0, 18), {220, 220, 220});
  }
  draw_frame_labels(image, top, top_view,
                    dataset.scenario + ": first frames, top view (vehicle frame, x right)");
  draw_frame_labels(image, side, side_view, "side view (x right, z up)");
  image.fill_rect(0, kTopHeight, kWidth, kTopHeight + 2, {90, 90, 90});
  image.write_png(png);
}

/// Writes every frame of the named LiDARs again without their per-point times: a driver that does
/// not publish them, or a conversion that dropped them.
void strip_point_times(const std::filesystem::path& dir, const sim::Dataset& dataset,
                       const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    const auto it = std::find_if(dataset.lidars.begin(), dataset.lidars.end(),
                                 [&](const auto& l) { return l.name == name; });
    if (it == dataset.lidars.end())
      throw UsageError("simulate: --no-point-times: no LiDAR named '" + name + "' in " +
                       dataset.scenario);
    for (std::size_t k = 0; k < it->timestamps.size(); ++k) {
      const auto file = dir / name / sim::frame_file_name(k);
      auto cloud = io::read_pcd<PointCloud<float>>(file);
      cloud.times.clear();
      io::write_pcd(file, cloud, io::PcdEncoding::binary);
    }
  }
}

void print_scenarios() {
  for (const auto& name : sim::scenario_names()) {
    const auto spec = sim::scenario(name);
    std::printf("%-14s %s\n", name.c_str(), spec ? spec->description.c_str() : "");
  }
}

}  // namespace

int run_simulate(int argc, char** argv) {
  CLI::App app(
      "Simulates a multi-LiDAR rig driving through a scene and writes a dataset folder with exact "
      "ground truth.",
      "ulc simulate");
  std::string scenario_name, out_dir, preview;
  double seconds = 20.0, rate = 10.0, time_offset = 0.0, steering_ramp = 0.0, parked_at = 0.0;
  long long seed = 1;
  bool list = false, quiet = false;
  std::vector<std::string> untimed;
  // --scenario and --out are required unless --list: checked after parsing.
  auto* scenario_option =
      app.add_option("--scenario", scenario_name, "a rig and scene (see --list)")
          ->type_name("NAME");
  auto* out_option = app.add_option("--out", out_dir, "dataset folder to write")->type_name("DIR");
  app.add_option("--seconds", seconds, "recorded duration, (0, 3600] s (default 20)")
      ->type_name("S");
  app.add_option("--seed", seed, "seed of scene, route, phases and noise (default 1)")
      ->type_name("N")
      ->check(CLI::Range(0LL, 1LL << 62));
  auto* rate_option =
      app.add_option("--rate", rate,
                     "frame rate of every LiDAR, [1, 100] Hz (default: the scenario's)")
          ->type_name("HZ");
  auto* offset_option =
      app.add_option("--time-offset", time_offset,
                     "clock offset of every target, [-1, 1] s: t_base_clock = t_target_clock + S")
          ->type_name("S");
  auto* ramp_option =
      app.add_option(
             "--steering-ramp", steering_ramp,
             "the vehicle follows its route averaged over M metres ([0, 50]), so that yaw rate and "
             "body roll ramp into turns (default 0: they step where a street meets a "
             "corner arc)")
          ->type_name("M");
  auto* parked_option =
      app.add_option("--parked-at", parked_at,
                     "the vehicle drives S seconds along its route, [0, 3600], and stands there "
                     "for the whole recording (a parked rig)")
          ->type_name("S");
  auto* preview_option =
      app.add_option("--preview", preview, "also draw every LiDAR's first frame, top-down and side")
          ->type_name("PNG");
  app.add_option("--no-point-times", untimed,
                 "write this LiDAR's frames without per-point times (repeatable)")
      ->type_name("LIDAR");
  app.add_flag("--list", list, "list the scenarios and exit");
  app.add_flag("--quiet", quiet, "no progress on stderr");
  if (parse_command_line(app, "simulate", argc, argv)) return kExitOk;
  if (list) {
    print_scenarios();
    return kExitOk;
  }
  if (scenario_option->count() == 0)
    throw UsageError("simulate: --scenario is required (see --list)");
  if (out_option->count() == 0) throw UsageError("simulate: --out is required");
  auto spec = sim::scenario(scenario_name);
  if (!spec)
    throw UsageError("simulate: unknown scenario '" + scenario_name +
                     "' (see `ulc simulate --list`)");
  // The numbers' ranges are checked here (CLI::Range would let NaN through).
  if (ramp_option->count() > 0) {
    if (!(steering_ramp >= 0.0 && steering_ramp <= 50.0))
      throw UsageError("simulate: option '--steering-ramp' must be in [0, 50] m");
    spec->motion.steering_ramp_m = steering_ramp;
  }
  sim::SimulationOptions options;
  options.seconds = seconds;
  if (!(options.seconds > 0 && options.seconds <= 3600))
    throw UsageError("simulate: option '--seconds' must be in (0, 3600]");
  options.seed = static_cast<std::uint64_t>(seed);
  if (rate_option->count() > 0) {
    if (!(rate >= 1 && rate <= 100))
      throw UsageError("simulate: option '--rate' must be in [1, 100] Hz");
    options.rate_hz = rate;
  }
  if (offset_option->count() > 0) {
    if (!(std::fabs(time_offset) <= 1.0))
      throw UsageError("simulate: option '--time-offset' must be within [-1, 1] s");
    options.target_clock_offset_s = time_offset;
  }
  if (parked_option->count() > 0) {
    if (!(parked_at >= 0.0 && parked_at <= 3600.0))
      throw UsageError("simulate: option '--parked-at' must be in [0, 3600] s");
    options.static_at_s = parked_at;
  }
  options.keep_frames = false;

  const std::filesystem::path out = out_dir;
  Progress progress("simulate", quiet);
  const auto result = sim::simulate_to_directory(
      out, *spec, options,
      [&](std::size_t done, std::size_t total) { progress.update(done, total); });
  if (!result.ok()) {
    std::fprintf(stderr, "ulc simulate: %s\n", result.reason.c_str());
    return kExitUsage;
  }
  strip_point_times(out, result.dataset, untimed);
  std::printf("wrote %s: scenario %s, %.1f s, seed %llu\n", out.string().c_str(),
              spec->name.c_str(), options.seconds, static_cast<unsigned long long>(options.seed));
  for (const auto& l : result.dataset.lidars)
    std::printf("  %-10s %-10s %4zu frames at %4.1f Hz, %9zu points, clock offset %+.3f s\n",
                l.name.c_str(), l.model.c_str(), l.timestamps.size(), l.rate_hz, l.points,
                l.clock_offset_s);
  std::printf("  ground truth: %s\n", (out / "ground_truth.json").string().c_str());
  if (preview_option->count() > 0) {
    write_preview(preview, out, result.dataset);
    std::printf("  preview: %s\n", preview.c_str());
  }
  return kExitOk;
}

}  // namespace ulc::app
