// `ulc calibrate`: the extrinsic of every target LiDAR against the base, through the stages asked
// for (terra, jeep, hots), written as the result file of docs/design.md and summarised on stdout.
// The targets form a rig (pipeline/rig.hpp): a target that fails against the base is routed
// through one that succeeded, and with two targets or more the cycles between them are closed.
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calibrate_frames.hpp"
#include "calibration_report.hpp"
#include "command_line.hpp"
#include "commands.hpp"
#include "drive_selection.hpp"
#include "fused_cloud.hpp"
#include "initial_extrinsic.hpp"
#include "lidar_input.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/rig.hpp"
#include "progress.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/result_entry.hpp"
#include "ulc/io/result_file.hpp"
#include "ulc/io/result_yaml.hpp"

namespace ulc::app {
namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

/// One bar (or plain lines) per stage of one calibration, labelled as the rig labels it:
/// "<target> <stage>", "<target> via <lidar> <stage>" or "cycle <i>-<j> <stage>".
class StageProgress {
 public:
  explicit StageProgress(bool quiet) : quiet_(quiet) {}
  void operator()(const std::string& stage, double fraction) {
    if (!bar_ || stage != stage_) {
      stage_ = stage;
      bar_ = std::make_unique<Progress>(stage, quiet_);
    }
    bar_->update_fraction(fraction);
  }

 private:
  bool quiet_;
  std::string stage_;
  std::unique_ptr<Progress> bar_;
};

std::vector<Stage> stages_option(const std::string& text) {
  const ParsedStages parsed = parse_stages(text);
  if (!parsed.ok()) throw UsageError("calibrate: option '--stages': " + parsed.error);
  return parsed.stages;
}

/// Fails before the work, not after it, when the result file's folder does not exist.
void require_output_folder(const std::string& output) {
  const std::filesystem::path folder = std::filesystem::path(output).parent_path();
  std::error_code ec;
  if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
    throw UsageError("calibrate: --output " + output + ": no such folder " + folder.string());
}

std::vector<Eigen::Vector3f> points_of(const PointCloud<float>& cloud) {
  return std::vector<Eigen::Vector3f>(cloud.points.begin(), cloud.points.end());
}

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
                         const std::optional<Selection>& selection, double budget) {
  io::PairResult r = io::to_pair_result(t.result, base, t.name);
  if (selection) r.stages["selection"] = selection_json(*selection, budget);
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

void print_summary(const io::PairResult& r) {
  std::printf("%s <- %s: %s%s%s\n", r.base.c_str(), r.target.c_str(), r.status.c_str(),
              r.reason.empty() ? "" : ": ", r.reason.c_str());
  if (!r.via.empty())
    std::printf("  route   %s <- %s <- %s (direct: %s)\n", r.base.c_str(), r.via.c_str(),
                r.target.c_str(), r.direct_status.c_str());
  // TERRA's later hypotheses ran (calibrate.hpp): say which one the result comes from.
  if (const io::Json* terra = io::find_member(r.stages, "terra")) {
    const io::Json* tried = io::find_member(*terra, "hypotheses");
    if (tried && tried->size() > 1)
      std::printf(
          "  terra   %zu hypotheses tried, the result from hypothesis %.0f "
          "(stages.terra.hypotheses)\n",
          tried->size(), terra->at("hypothesis_used").get<double>() + 1.0);
  }
  if (const io::Json* s = io::find_member(r.stages, "selection"); s && s->at("applied").get<bool>())
    std::printf("  stretch %.0f-%.0f s of the %.0f s drive (stages.selection)\n",
                s->at("start_s").get<double>(), s->at("end_s").get<double>(),
                s->at("drive_s").get<double>());
  for (const auto& d : r.unobservable) std::printf("  free    %s\n", d.words.c_str());
  const Eigen::Vector3d t = r.T_base_target.translation();
  const Eigen::Vector3d rpy = ulc::rpy_from_rotation(r.T_base_target.linear()) * kDeg;
  std::printf("  xyz_m   %9.4f %9.4f %9.4f\n", t.x(), t.y(), t.z());
  std::printf("  rpy_deg %9.3f %9.3f %9.3f\n", rpy.x(), rpy.y(), rpy.z());
  if (const io::Json* hots = io::find_member(r.stages, "hots");
      hots && hots->at("status").get<std::string>() != "skipped")
    std::printf("  time_offset_ms %.2f\n", r.time_offset_s ? *r.time_offset_s * 1e3 : 0.0);
  // What the data could not vouch for (pipeline/vouch.hpp), when it applies.
  if (r.success && !r.clock.is_null() && r.clock.at("source").get<std::string>() == "not_estimated")
    std::printf("  clock   %s\n", r.clock.at("note").get<std::string>().c_str());
  if (r.point_times.is_object())
    for (const char* lidar : {"base", "target"})
      if (const io::Json& p = r.point_times.at(lidar);
          p.at("source").get<std::string>() != "per_point")
        std::printf("  times   %s (%s): %s\n",
                    lidar == std::string("base") ? r.base.c_str() : r.target.c_str(),
                    p.at("source").get<std::string>().c_str(),
                    p.at("note").get<std::string>().c_str());
  std::printf("  time_s  terra %.2f  jeep %.2f  odometry %.2f  hots %.2f  total %.2f\n",
              r.timing_s.at("terra").get<double>(), r.timing_s.at("jeep").get<double>(),
              r.timing_s.at("odometry").get<double>(), r.timing_s.at("hots").get<double>(),
              r.timing_s.at("total").get<double>());
}

void print_cycle(const io::CycleResult& c) {
  const std::string& base = c.lidars.at(0);
  std::printf("cycle %s -> %s -> %s -> %s: ", base.c_str(), c.lidars.at(1).c_str(),
              c.lidars.at(2).c_str(), base.c_str());
  if (c.rotation_deg && c.translation_m)
    std::printf("closure %.3f deg %.2f cm\n", *c.rotation_deg, *c.translation_m * 100.0);
  else
    std::printf("not closed: %s -> %s %s: %s\n", c.lidars.at(1).c_str(), c.lidars.at(2).c_str(),
                c.status.c_str(), c.reason.c_str());
}

/// What the command line of `ulc calibrate` says.
struct CalibrateArgs {
  std::string base_spec, output, format = "json", merged_cloud, report_png,
                                 stages_text = "terra,jeep,hots", initial;
  std::vector<std::string> target_specs;
  long long frame_index = 0, frames = static_cast<long long>(jeep::JeepOptions{}.frames),
            threads = 0;
  bool synced_clocks = false, no_route = false, no_cycles = false, quiet = false;
  InputArgs input;
  // Set when the user gave them.
  CLI::Option *output_option = nullptr, *merged_option = nullptr, *report_option = nullptr,
              *initial_option = nullptr, *threads_option = nullptr;
  double budget = SelectionOptions{}.budget_s;  ///< --budget
  double time_offset = 0.0;  ///< --time-offset: a known offset of every target's clock
  CLI::Option* time_offset_option = nullptr;

  bool has(const CLI::Option* o) const { return o->count() > 0; }
};

void add_source_options(CLI::App& app, CalibrateArgs& a) {
  app.add_option(
         "--base", a.base_spec,
         "the base LiDAR: a frame folder, a cloud file, or FILE:TOPIC of a recording (.bag, "
         ".mcap, rosbag2 folder, .db3); add =NAME to name it")
      ->type_name("SOURCE")
      ->required();
  app.add_option("--target", a.target_specs, "a target LiDAR, as --base (repeatable)")
      ->type_name("SOURCE")
      ->required()
      ->allow_extra_args(false);
  add_input_options(app, a.input);
  app.add_option("--budget", a.budget,
                 "seconds of data HOTS calibrates on: a longer drive is surveyed and its best "
                 "stretch of S seconds used (stages.selection says which and why); 0: the whole "
                 "drive; --start / --duration choose the stretch yourself (default 60)")
      ->type_name("S")
      ->check(CLI::Range(0.0, 1e9));
}

void add_output_options(CLI::App& app, CalibrateArgs& a) {
  a.output_option =
      app.add_option("--output", a.output, "write the result file (docs/design.md) here")
          ->type_name("FILE");
  app.add_option("--format", a.format,
                 "format of --output (default json; yaml adds ROS and URDF forms of each "
                 "extrinsic)")
      ->check(CLI::IsMember({"json", "yaml"}));
  a.merged_option =
      app.add_option("--merged-cloud", a.merged_cloud,
                     "write every LiDAR's first used frame in the base frame, one colour per LiDAR")
          ->type_name("PCD");
  a.report_option =
      app.add_option("--report", a.report_png,
                     "draw the fused frames before (initial guess) and after calibration")
          ->type_name("PNG");
  app.add_flag("--quiet", a.quiet, "no progress on stderr");
}

void add_stage_options(CLI::App& app, CalibrateArgs& a) {
  app.add_option("--stages", a.stages_text,
                 "an ordered subset of terra,jeep,hots (default terra,jeep,hots)")
      ->type_name("LIST");
  a.initial_option =
      app.add_option("--initial", a.initial,
                     "\"x y z roll pitch yaw\" (m, deg; R = Rz Ry Rx) or a result file; needed "
                     "when the stages skip terra")
          ->type_name("GUESS");
  app.add_option("--frame-index", a.frame_index,
                 "TERRA's frame, and the first frame of JEEP and HOTS (default 0)")
      ->type_name("N")
      ->check(CLI::Range(0LL, 1000000000LL));
  app.add_option("--frames", a.frames, "frame pairs JEEP uses (default 5)")
      ->type_name("K")
      ->check(CLI::Range(1LL, 100000LL));
  a.threads_option = app.add_option("--threads", a.threads, "worker threads (default: all cores)")
                         ->type_name("N")
                         ->check(CLI::Range(1LL, 1024LL));
  app.add_flag("--synced-clocks", a.synced_clocks,
               "the LiDARs' clocks are synchronised (PTP, GPS): HOTS estimates no clock offset "
               "(for short drives that cannot pin one down)");
  a.time_offset_option =
      app.add_option(
             "--time-offset", a.time_offset,
             "the clocks' known offset, t_base = t_target + S, [-1, 1] s, for every target: "
             "no offset is estimated or checked")
          ->type_name("S")
          ->excludes("--synced-clocks");
  app.add_flag("--no-route", a.no_route,
               "do not calibrate a failed target through another target that did calibrate");
  app.add_flag("--no-cycles", a.no_cycles,
               "do not check the cycles base -> i -> j -> base (two targets or more)");
}

/// The pipeline's options from the command line; usage errors before any frame is read.
CalibrateOptions calibrate_options(const CalibrateArgs& a) {
  CalibrateOptions options;
  options.stages = stages_option(a.stages_text);
  const bool run_terra = has_stage(options.stages, Stage::terra);
  const bool has_initial = a.has(a.initial_option);
  if (run_terra && has_initial)
    throw UsageError(
        "calibrate: option '--initial' is only used when the stages skip terra (TERRA needs no "
        "guess); use --stages jeep,hots or hots with it");
  if (!run_terra && !has_initial)
    throw UsageError("calibrate: --stages " + stages_to_string(options.stages) +
                     " needs an initial extrinsic: --initial \"x y z roll pitch yaw\" or "
                     "--initial FILE.json");
  if (a.synced_clocks) options.time_offset_s = 0.0;
  if (a.has(a.time_offset_option)) {
    if (!(std::fabs(a.time_offset) <= 1.0))
      throw UsageError("calibrate: option '--time-offset' must be within [-1, 1] s");
    options.time_offset_s = a.time_offset;
  }
  options.tuning.jeep.frames = static_cast<std::size_t>(a.frames);
  if (!run_terra) (void)parse_initial(a.initial, "", "");  // fail before any loading
  for (const CLI::Option* file_option : {a.output_option, a.merged_option, a.report_option})
    if (a.has(file_option)) require_output_folder(file_option->as<std::string>());
  return options;
}

/// f() run with --threads worker threads when given (else TBB's default).
template <class F>
auto in_arena(const CalibrateArgs& a, const F& f) {
  if (!a.has(a.threads_option)) return f();
  tbb::task_arena arena(static_cast<int>(a.threads));
  return arena.execute(f);
}

/// Every LiDAR's frames from frame_index, as many as the stages need, read on demand for the
/// whole rig (routes and cycles pair targets too); the base's are shared by all targets.
struct LoadedRig {
  std::optional<Selection> selection;  ///< when the drive was surveyed
  std::vector<std::unique_ptr<LidarInput>> inputs;
  std::vector<StreamedFrames> frames;  ///< the base's first
  std::vector<RigLidar<FrameSource>> lidars;
};

/// A drive longer than the budget (by more than a frame) and no --start / --duration: the
/// base's drive is surveyed and the inputs opened again on its best stretch
/// (pipeline/selection.hpp).
void choose_stretch(const CalibrateArgs& a, const std::vector<LidarSpec>& specs, InputOptions input,
                    LoadedRig& rig) {
  const LidarInput& base = *rig.inputs.front();
  const bool user_window = input.window.start_s || input.window.duration_s;
  if (!(a.budget > 0.0) || user_window || base.span_s() <= a.budget + base.period()) return;
  SelectionOptions so;
  so.budget_s = a.budget;
  rig.selection = in_arena(a, [&] { return survey_drive(base, so, a.quiet); });
  if (!rig.selection->applied) return;
  input.window.start_s = rig.selection->start_s;
  input.window.duration_s = a.budget;
  rig.inputs = open_lidar_inputs(specs, input, "calibrate");
}

LoadedRig load_rig(const CalibrateArgs& a, const CalibrateOptions& options) {
  const bool run_jeep = has_stage(options.stages, Stage::jeep);
  const bool run_hots = has_stage(options.stages, Stage::hots);
  const auto frame_index = static_cast<std::size_t>(a.frame_index);
  std::vector<LidarSpec> specs{parse_lidar_spec(a.base_spec, "calibrate", "base")};
  for (const auto& t : a.target_specs) specs.push_back(parse_lidar_spec(t, "calibrate", "target"));
  LoadedRig rig;
  const InputOptions input = input_options(a.input, "calibrate");
  rig.inputs = open_lidar_inputs(specs, input, "calibrate");
  print_input_warnings(rig.inputs, "calibrate");
  if (run_hots) choose_stretch(a, specs, input, rig);
  const LidarInput& base = *rig.inputs.front();
  const std::size_t base_count = run_hots   ? kAllFrames
                                 : run_jeep ? jeep_only_count(options, base.period())
                                            : 1;
  for (std::size_t k = 0; k < rig.inputs.size(); ++k) {
    const LidarInput& lidar = *rig.inputs[k];
    const std::size_t count = k == 0 || run_hots ? base_count
                              : run_jeep ? covering_count(base.period(), lidar.period(), base_count)
                                         : 1;
    rig.frames.push_back(lidar.stream(frame_index, count));
    require_frame(lidar, rig.frames.back(), frame_index);
  }
  for (std::size_t k = 0; k < rig.inputs.size(); ++k) {
    RigLidar<FrameSource> l{
        rig.inputs[k]->name(), rig.frames[k].frames.get(), &rig.frames[k].times, {}};
    if (k > 0 && !has_stage(options.stages, Stage::terra))
      l.initial = parse_initial(a.initial, base.name(), l.name);
    rig.lidars.push_back(std::move(l));
  }
  return rig;
}

RigCalibration run_rig(const CalibrateArgs& a, const CalibrateOptions& options,
                       const LoadedRig& loaded) {
  RigOptions rig_options;
  rig_options.pair = options;
  rig_options.pair.frame_index = 0;  // the loaded frames start at frame_index
  rig_options.route = !a.no_route;
  rig_options.cycles = !a.no_cycles && loaded.inputs.size() >= 3;
  rig_options.cycle_stages = cycle_stages(options.stages);
  StageProgress progress(a.quiet);
  rig_options.pair.progress = [&progress](const std::string& stage, double f) {
    progress(stage, f);
  };
  RigCalibration rig = in_arena(a, [&] { return calibrate_rig(loaded.lidars, 0, rig_options); });
  // A frame that could not be read reached the stages empty: the result is not to be trusted.
  for (std::size_t k = 0; k < loaded.frames.size(); ++k)
    if (const std::string why = loaded.frames[k].frames->error(); !why.empty())
      throw io::IoError(loaded.inputs[k]->source(), "", "a frame could not be read: " + why);
  if (rig.status == RigStatus::invalid_input) throw UsageError("calibrate: " + rig.reason);
  return rig;
}

/// The result file's entries, printed as they are made, and the pictures' clouds: a failed
/// target is drawn where its guess put it, in both panels.
struct RigOutputs {
  std::vector<io::PairResult> results;
  std::vector<io::CycleResult> cycles;
  std::vector<FusedPart> fused;
  std::vector<ReportCloud> report;
};

RigOutputs rig_outputs(const CalibrateArgs& a, const LoadedRig& loaded, const RigCalibration& rig) {
  const std::string& base = loaded.lidars.front().name;
  RigOutputs out;
  out.fused.push_back({points_of(loaded.frames.front().frames->load(0)), Isometry3d::Identity()});
  out.report.push_back(
      {base, out.fused.front().points, Isometry3d::Identity(), Isometry3d::Identity()});
  const bool pictures = a.has(a.merged_option) || a.has(a.report_option);
  for (const RigTarget& t : rig.targets) {
    out.results.push_back(
        rig_entry(t, base, static_cast<std::size_t>(a.frame_index), loaded.selection, a.budget));
    print_summary(out.results.back());
    if (!pictures) continue;
    const Isometry3d before = loaded.lidars[t.lidar].initial.value_or(Isometry3d::Identity());
    const Isometry3d after = t.ok() ? t.result.T_base_target : before;
    out.fused.push_back({points_of(loaded.frames[t.lidar].frames->load(0)), after});
    out.report.push_back({t.name, out.fused.back().points, before, after});
  }
  for (const RigCycle& c : rig.cycles) {
    out.cycles.push_back(cycle_entry(c, base));
    print_cycle(out.cycles.back());
  }
  return out;
}

void write_outputs(const CalibrateArgs& a, const RigOutputs& out) {
  if (a.has(a.output_option)) {
    if (a.format == "yaml")
      io::write_result_yaml(a.output, out.results, out.cycles);
    else
      io::write_result_file(a.output, out.results, out.cycles);
    std::printf("wrote %s\n", a.output.c_str());
  }
  if (a.has(a.merged_option)) {
    write_fused_cloud(a.merged_cloud, out.fused);
    std::printf("wrote %s\n", a.merged_cloud.c_str());
  }
  if (a.has(a.report_option)) {
    write_calibration_report(a.report_png, out.report);
    std::printf("wrote %s\n", a.report_png.c_str());
  }
}

}  // namespace

int run_calibrate(int argc, char** argv) {
  CLI::App app(
      "Finds the extrinsic T_base_target of each target LiDAR against the base, with no initial "
      "guess (TERRA), refined (JEEP), then over every frame with the clock offset (odometry + "
      "HOTS). A target that fails against the base is calibrated through another target that "
      "succeeded (\"via\" in the result file); with two targets or more, each pair of targets is "
      "calibrated (terra,jeep) to report how far the cycle base -> i -> j -> base fails to close. "
      "Exit 0: every target calibrated, directly or through another; 1: some did not (the result "
      "file says why); 2: bad usage or input.",
      "ulc calibrate");
  CalibrateArgs args;
  add_source_options(app, args);
  add_output_options(app, args);
  add_stage_options(app, args);
  if (parse_command_line(app, "calibrate", argc, argv)) return kExitOk;
  const CalibrateOptions options = calibrate_options(args);
  const LoadedRig loaded = load_rig(args, options);
  const RigCalibration rig = run_rig(args, options, loaded);
  const RigOutputs out = rig_outputs(args, loaded, rig);
  write_outputs(args, out);
  for (const auto& r : out.results)
    if (!r.success) return kExitFailed;
  return kExitOk;
}

}  // namespace ulc::app
