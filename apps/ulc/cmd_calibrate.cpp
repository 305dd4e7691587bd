// `ulc calibrate`: the extrinsic of every target LiDAR against the base, through the stages asked
// for (terra, jeep, hots), written as the result file of docs/design.md and summarised on stdout.
// The targets form a rig (pipeline/rig.hpp): a target that fails against the base is routed
// through one that succeeded, and with two targets or more the cycles between them are closed.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "calibration_report.hpp"
#include "command_line.hpp"
#include "commands.hpp"
#include "fused_cloud.hpp"
#include "lidar_input.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/rig.hpp"
#include "pipeline/selection.hpp"
#include "progress.hpp"
#include "rig_run.hpp"
#include "ulc/core/lie.hpp"
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
  // A rig that stood still for the whole recording is calibrated as a snapshot (stillness.hpp).
  if (const io::Json* hots = io::find_member(r.stages, "hots"))
    if (const io::Json* still = io::find_member(*hots, "stillness");
        still && still->is_object() && still->at("still").get<bool>())
      std::printf("  parked  %s (stages.hots.stillness)\n",
                  still->at("reason").get<std::string>().c_str());
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
  bool synced_clocks = false, no_route = false, no_cycles = false, quiet = false,
       base_odometry = false, joint_odometry = false;
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
  app.add_flag("--base-odometry", a.base_odometry,
               "HOTS starts from the base LiDAR's own odometry; it and HOTS's work on the base "
               "are done once for every target (the default on drives of 30 s or more whose "
               "base sees all around; docs/pipeline.md, \"The odometry\")");
  app.add_flag("--joint-odometry", a.joint_odometry,
               "HOTS starts from the odometry of both LiDARs, run for every hypothesis and "
               "target (the default on shorter drives or with a narrow base)")
      ->excludes("--base-odometry");
  app.add_flag("--no-route", a.no_route,
               "do not calibrate a failed target through another target that did calibrate");
  app.add_flag("--no-cycles", a.no_cycles,
               "do not check the cycles base -> i -> j -> base (two targets or more)");
}

/// The pipeline's options from the command line; usage errors before any frame is read.
CalibrateOptions calibrate_options(const CalibrateArgs& a) {
  CalibrateChoices c;
  c.stages = a.stages_text;
  if (a.has(a.initial_option)) c.initial = a.initial;
  c.synced_clocks = a.synced_clocks;
  if (a.has(a.time_offset_option)) c.time_offset_s = a.time_offset;
  c.frames = static_cast<std::size_t>(a.frames);
  if (a.base_odometry) c.odometry = HotsOdometry::base;
  if (a.joint_odometry) c.odometry = HotsOdometry::joint;
  const CalibrateOptions options = calibrate_options(c);
  for (const CLI::Option* file_option : {a.output_option, a.merged_option, a.report_option})
    if (a.has(file_option)) require_output_folder(file_option->as<std::string>());
  return options;
}

/// --threads, or 0 (TBB's default).
std::size_t threads_of(const CalibrateArgs& a) {
  return a.has(a.threads_option) ? static_cast<std::size_t>(a.threads) : 0;
}

/// The sources of the command line, base first.
RigRequest rig_request(const CalibrateArgs& a) {
  RigRequest r;
  r.specs.push_back(parse_lidar_spec(a.base_spec, "calibrate", "base"));
  for (const auto& t : a.target_specs)
    r.specs.push_back(parse_lidar_spec(t, "calibrate", "target"));
  r.input = input_options(a.input, "calibrate");
  r.frame_index = static_cast<std::size_t>(a.frame_index);
  r.initial = a.initial;
  r.route = !a.no_route;
  r.cycles = !a.no_cycles;
  r.budget_s = a.budget;
  r.threads = threads_of(a);
  r.quiet = a.quiet;
  return r;
}

RigCalibration calibrate_loaded_rig(const CalibrateArgs& a, const CalibrateOptions& options,
                                    const LoadedRig& loaded) {
  RigOptions rig = rig_options(options, !a.no_route, !a.no_cycles, loaded.inputs.size());
  rig.pair.frame_index = 0;  // the loaded frames start at frame_index
  StageProgress progress(a.quiet);
  rig.pair.progress = [&progress](const std::string& stage, double f) { progress(stage, f); };
  return run_rig(loaded, rig, threads_of(a));
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
  io::ResultDocument entries =
      rig_entries(rig, static_cast<std::size_t>(a.frame_index), loaded.selection, loaded.budget_s);
  out.fused.push_back({points_of(loaded.frames.front().frames->load(0)), Isometry3d::Identity()});
  out.report.push_back(
      {base, out.fused.front().points, Isometry3d::Identity(), Isometry3d::Identity()});
  const bool pictures = a.has(a.merged_option) || a.has(a.report_option);
  out.results = std::move(entries.results);
  out.cycles = std::move(entries.cycles);
  for (std::size_t k = 0; k < rig.targets.size(); ++k) {
    const RigTarget& t = rig.targets[k];
    print_summary(out.results[k]);
    if (!pictures) continue;
    const Isometry3d before = loaded.lidars[t.lidar].initial.value_or(Isometry3d::Identity());
    const Isometry3d after = t.ok() ? t.result.T_base_target : before;
    out.fused.push_back({points_of(loaded.frames[t.lidar].frames->load(0)), after});
    out.report.push_back({t.name, out.fused.back().points, before, after});
  }
  for (const io::CycleResult& c : out.cycles) print_cycle(c);
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
  const RigRequest request = rig_request(args);
  const LoadedRig loaded = load_rig(request, options);
  const RigCalibration rig = calibrate_loaded_rig(args, options, loaded);
  const RigOutputs out = rig_outputs(args, loaded, rig);
  write_outputs(args, out);
  for (const auto& r : out.results)
    if (!r.success) return kExitFailed;
  return kExitOk;
}

}  // namespace ulc::app
