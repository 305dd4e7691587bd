#include "rig_run.hpp"

#include <tbb/task_arena.h>

#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "calibrate_frames.hpp"
#include "drive_selection.hpp"
#include "initial_extrinsic.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/result_entry.hpp"
#include "usage_error.hpp"

namespace ulc::app {
namespace {

/// The stages of the cycle checks: the pair stages without HOTS (TERRA + JEEP is the cheap,
/// independent check); HOTS alone leaves JEEP, started from the chained extrinsics.
std::vector<Stage> cycle_stages(const std::vector<Stage>& stages) {
  std::vector<Stage> out;
  for (const Stage s : stages)
    if (s != Stage::hots) out.push_back(s);
  if (out.empty()) out.push_back(Stage::jeep);
  return out;
}

/// The result-file entry of one target of the rig: its calibration, and for a routed target
/// the LiDAR it went through and why the direct attempt failed.
io::PairResult rig_entry(const RigTarget& t, const std::string& base, std::size_t frame_index,
                         const std::optional<Selection>& selection, double budget_s) {
  io::PairResult r = io::to_pair_result(t.result, base, t.name);
  if (selection) r.stages["selection"] = selection_json(*selection, budget_s);
  if (r.stages.contains("terra")) r.stages["terra"]["frame_index"] = frame_index;
  if (t.routed()) {
    r.via = t.via_name;
    r.direct_status = to_string(t.direct.status);
    r.direct_reason = t.direct.reason;
  }
  return r;
}

io::CycleResult cycle_entry(const RigCycle& c, const std::string& base) {
  io::CycleResult r;
  r.lidars = {base, c.name_i, c.name_j};
  r.status = to_string(c.pair.status);
  r.reason = c.pair.reason;
  r.rotation_deg = c.rotation_deg;
  r.translation_m = c.translation_m;
  return r;
}

std::vector<Stage> stages_option(const std::string& text) {
  const ParsedStages parsed = parse_stages(text);
  if (!parsed.ok()) throw UsageError("calibrate: option '--stages': " + parsed.error);
  return parsed.stages;
}

/// How many frames of LiDAR k to read (calibrate_frames.hpp).
std::size_t frames_to_read(const CalibrateOptions& options, const LidarInput& base,
                           const LidarInput& lidar, bool is_base) {
  const bool run_jeep = has_stage(options.stages, Stage::jeep);
  const bool run_hots = has_stage(options.stages, Stage::hots);
  const std::size_t base_count = run_hots   ? kAllFrames
                                 : run_jeep ? jeep_only_count(options, base.period())
                                            : 1;
  if (is_base || run_hots) return base_count;
  return run_jeep ? covering_count(base.period(), lidar.period(), base_count) : 1;
}

/// f() run with `threads` worker threads (0: TBB's default).
template <class F>
auto in_arena(std::size_t threads, const F& f) {
  if (threads == 0) return f();
  tbb::task_arena arena(static_cast<int>(threads));
  return arena.execute(f);
}

/// A drive longer than the budget (by more than a frame) and no --start / --duration: the
/// base's drive is surveyed and the inputs opened again on its best stretch
/// (pipeline/selection.hpp).
void choose_stretch(const RigRequest& request, LoadedRig& rig) {
  const LidarInput& base = *rig.inputs.front();
  InputOptions input = request.input;
  const bool user_window = input.window.start_s || input.window.duration_s;
  const double budget = request.budget_s;
  if (!(budget > 0.0) || user_window || base.span_s() <= budget + base.period()) return;
  SelectionOptions so;
  so.budget_s = budget;
  rig.budget_s = budget;
  rig.selection = in_arena(request.threads, [&] { return survey_drive(base, so, request.quiet); });
  if (!rig.selection->applied) return;
  input.window.start_s = rig.selection->start_s;
  input.window.duration_s = budget;
  rig.inputs = open_lidar_inputs(request.specs, input, "calibrate");
}

template <class Frames>
RigCalibration calibrate_in_arena(const std::vector<RigLidar<Frames>>& lidars,
                                  const RigOptions& options, std::size_t threads) {
  return in_arena(threads, [&] { return calibrate_rig(lidars, 0, options); });
}

void require_valid(const RigCalibration& rig) {
  if (rig.status == RigStatus::invalid_input) throw UsageError("calibrate: " + rig.reason);
}

}  // namespace

CalibrateOptions calibrate_options(const CalibrateChoices& c) {
  CalibrateOptions options;
  options.stages = stages_option(c.stages);
  const bool run_terra = has_stage(options.stages, Stage::terra);
  if (run_terra && c.initial)
    throw UsageError(
        "calibrate: option '--initial' is only used when the stages skip terra (TERRA needs no "
        "guess); use --stages jeep,hots or hots with it");
  if (!run_terra && !c.initial)
    throw UsageError("calibrate: --stages " + stages_to_string(options.stages) +
                     " needs an initial extrinsic: --initial \"x y z roll pitch yaw\" or "
                     "--initial FILE.json");
  if (c.synced_clocks && c.time_offset_s)
    throw UsageError("calibrate: --time-offset excludes --synced-clocks");
  if (c.synced_clocks) options.time_offset_s = 0.0;
  if (c.time_offset_s) {
    if (!(std::fabs(*c.time_offset_s) <= 1.0))
      throw UsageError("calibrate: option '--time-offset' must be within [-1, 1] s");
    options.time_offset_s = c.time_offset_s;
  }
  if (c.frames < 1) throw UsageError("calibrate: option '--frames' must be at least 1");
  options.tuning.jeep.frames = c.frames;
  options.tuning.hots_odometry = c.odometry;
  if (!run_terra) (void)parse_initial(*c.initial, "", "");  // fail before any loading
  return options;
}

LoadedRig load_rig(const RigRequest& request, const CalibrateOptions& options) {
  LoadedRig rig;
  rig.inputs = open_lidar_inputs(request.specs, request.input, "calibrate");
  print_input_warnings(rig.inputs, "calibrate");
  if (has_stage(options.stages, Stage::hots)) choose_stretch(request, rig);
  const LidarInput& base = *rig.inputs.front();
  for (std::size_t k = 0; k < rig.inputs.size(); ++k) {
    const LidarInput& lidar = *rig.inputs[k];
    rig.frames.push_back(
        lidar.stream(request.frame_index, frames_to_read(options, base, lidar, k == 0)));
    require_frame(lidar, rig.frames.back(), request.frame_index);
  }
  for (std::size_t k = 0; k < rig.inputs.size(); ++k) {
    RigLidar<FrameSource> l{
        rig.inputs[k]->name(), rig.frames[k].frames.get(), &rig.frames[k].times, {}};
    if (k > 0 && !has_stage(options.stages, Stage::terra))
      l.initial = parse_initial(request.initial, base.name(), l.name);
    rig.lidars.push_back(std::move(l));
  }
  return rig;
}

RigOptions rig_options(const CalibrateOptions& options, bool route, bool cycles,
                       std::size_t lidar_count) {
  RigOptions r;
  r.pair = options;
  r.route = route;
  r.cycles = cycles && lidar_count >= 3;
  r.cycle_stages = cycle_stages(options.stages);
  return r;
}

RigCalibration run_rig(const std::vector<RigLidar<FrameSource>>& lidars, const RigOptions& options,
                       std::size_t threads) {
  RigCalibration rig = calibrate_in_arena(lidars, options, threads);
  require_valid(rig);
  return rig;
}

RigCalibration run_rig(const LoadedRig& loaded, const RigOptions& options, std::size_t threads) {
  RigCalibration rig = calibrate_in_arena(loaded.lidars, options, threads);
  for (std::size_t k = 0; k < loaded.frames.size(); ++k)
    if (const std::string why = loaded.frames[k].frames->error(); !why.empty())
      throw io::IoError(loaded.inputs[k]->source(), "", "a frame could not be read: " + why);
  require_valid(rig);
  return rig;
}

io::ResultDocument rig_entries(const RigCalibration& rig, std::size_t frame_index,
                               const std::optional<Selection>& selection, double budget_s) {
  io::ResultDocument doc;
  for (const RigTarget& t : rig.targets)
    doc.results.push_back(rig_entry(t, rig.base_name, frame_index, selection, budget_s));
  for (const RigCycle& c : rig.cycles) doc.cycles.push_back(cycle_entry(c, rig.base_name));
  return doc;
}

}  // namespace ulc::app
