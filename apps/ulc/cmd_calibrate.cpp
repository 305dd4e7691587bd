// `ulc calibrate`: the extrinsic of every target LiDAR against the base, through the stages asked
// for (terra, jeep, hots), written as the result file of DESIGN.md and summarised on stdout.
#include <tbb/task_arena.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calibrate_frames.hpp"
#include "calibration_report.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "fused_cloud.hpp"
#include "initial_extrinsic.hpp"
#include "progress.hpp"
#include "ulc/calibrate.hpp"
#include "ulc/calibrate/result_entry.hpp"
#include "ulc/io/result_file.hpp"
#include "ulc/io/result_yaml.hpp"
#include "ulc/io/sequence.hpp"

namespace ulc::app {
namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

/// One bar (or plain lines) per stage of one target, labelled "<target> <stage>".
class StageProgress {
 public:
  StageProgress(std::string target, bool quiet) : target_(std::move(target)), quiet_(quiet) {}
  void operator()(const std::string& stage, double fraction) {
    if (!bar_ || stage != stage_) {
      stage_ = stage;
      bar_ = std::make_unique<Progress>(target_ + " " + stage, quiet_);
    }
    bar_->update(static_cast<std::size_t>(fraction * 100.0 + 0.5), 100);
  }

 private:
  std::string target_;
  bool quiet_;
  std::string stage_;
  std::unique_ptr<Progress> bar_;
};

std::vector<Stage> stages_option(const cli::Args& args) {
  const ParsedStages parsed = parse_stages(args.get("stages", "terra,jeep,hots"));
  if (!parsed.ok()) throw cli::UsageError("calibrate: option '--stages': " + parsed.error);
  for (const Stage s : parsed.stages)
    if (!stage_available(s))
      throw cli::UsageError(std::string("calibrate: option '--stages': stage '") + to_string(s) +
                            "' is not available in this build");
  return parsed.stages;
}

/// Fails before the work, not after it, when the result file's folder does not exist.
void require_output_folder(const std::string& output) {
  const std::filesystem::path folder = std::filesystem::path(output).parent_path();
  std::error_code ec;
  if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
    throw cli::UsageError("calibrate: --output " + output + ": no such folder " + folder.string());
}

std::vector<Eigen::Vector3f> points_of(const PointCloud<float>& cloud) {
  return std::vector<Eigen::Vector3f>(cloud.points.begin(), cloud.points.end());
}

void print_summary(const io::PairResult& r) {
  std::printf("%s <- %s: %s%s%s\n", r.base.c_str(), r.target.c_str(), r.status.c_str(),
              r.reason.empty() ? "" : ": ", r.reason.c_str());
  const Eigen::Vector3d t = r.T_base_target.translation();
  const Eigen::Vector3d rpy = ulc::rpy_from_rotation(r.T_base_target.linear()) * kDeg;
  std::printf("  xyz_m   %9.4f %9.4f %9.4f\n", t.x(), t.y(), t.z());
  std::printf("  rpy_deg %9.3f %9.3f %9.3f\n", rpy.x(), rpy.y(), rpy.z());
  if (const io::Json* hots = r.stages.find("hots");
      hots && hots->at("status").as_string() != "skipped")
    std::printf("  time_offset_ms %.2f\n", r.time_offset_s ? *r.time_offset_s * 1e3 : 0.0);
  std::printf("  time_s  terra %.2f  jeep %.2f  odometry %.2f  hots %.2f  total %.2f\n",
              r.timing_s.at("terra").as_number(), r.timing_s.at("jeep").as_number(),
              r.timing_s.at("odometry").as_number(), r.timing_s.at("hots").as_number(),
              r.timing_s.at("total").as_number());
}

}  // namespace

int run_calibrate(int argc, char** argv) {
  cli::Args args("calibrate");
  args.option("base", "PATH", "the base LiDAR: a frame folder or one frame file", true)
      .option("target", "PATH", "a target LiDAR: a frame folder or one frame file", true, true)
      .option("output", "FILE", "write the result file (DESIGN.md) here")
      .option("format", "json|yaml",
              "format of --output (default json; yaml adds ROS and URDF forms of each extrinsic)")
      .option("merged-cloud", "PCD",
              "write every LiDAR's first used frame in the base frame, one colour per LiDAR")
      .option("report", "PNG", "draw the fused frames before (initial guess) and after calibration")
      .option("stages", "LIST", "an ordered subset of terra,jeep,hots (default terra,jeep,hots)")
      .option("initial", "GUESS",
              "\"x y z roll pitch yaw\" (m, deg; R = Rz Ry Rx) or a result file; needed when "
              "the stages skip terra")
      .option("frame-index", "N", "TERRA's frame, and the first frame of JEEP and HOTS (default 0)")
      .option("frames", "K", "frame pairs JEEP uses (default 5)")
      .option("threads", "N", "worker threads (default: all cores)")
      .flag("quiet", "no progress on stderr")
      .flag("help", "show this help");
  args.parse(argc, argv, 1);
  if (args.has("help")) {
    std::printf("%s",
                args.help_text("Finds the extrinsic T_base_target of each target LiDAR "
                               "against the base, with no initial guess (TERRA), "
                               "refined (JEEP), then over every frame with the clock "
                               "offset (odometry + HOTS). Exit 0: all calibrated; 1: some did not "
                               "(the result file says why); 2: bad usage or input.")
                    .c_str());
    return kExitOk;
  }

  CalibrateOptions options;
  options.stages = stages_option(args);
  const bool run_terra = has_stage(options.stages, Stage::terra);
  const bool run_jeep = has_stage(options.stages, Stage::jeep);
  const bool run_hots = has_stage(options.stages, Stage::hots);
  if (run_terra && args.has("initial"))
    throw cli::UsageError(
        "calibrate: option '--initial' is only used when the stages skip terra (TERRA needs no "
        "guess); use --stages jeep,hots or hots with it");
  if (!run_terra && !args.has("initial"))
    throw cli::UsageError("calibrate: --stages " + stages_to_string(options.stages) +
                          " needs an initial extrinsic: --initial \"x y z roll pitch yaw\" or "
                          "--initial FILE.json");
  const auto frame_index =
      static_cast<std::size_t>(args.get_int("frame-index", 0, 0, 1000000000LL));
  options.jeep.frames = static_cast<std::size_t>(
      args.get_int("frames", static_cast<long long>(options.jeep.frames), 1, 100000));
  std::optional<tbb::task_arena> arena;
  if (args.has("threads")) arena.emplace(static_cast<int>(args.get_int("threads", 1, 1, 1024)));
  if (!run_terra) (void)parse_initial(args.get("initial"), "", "");  // fail before any loading
  const std::string format = args.get("format", "json");
  if (format != "json" && format != "yaml")
    throw cli::UsageError("calibrate: option '--format': expected json or yaml, got '" + format +
                          "'");
  for (const char* file_option : {"output", "merged-cloud", "report"})
    if (args.has(file_option)) require_output_folder(args.get(file_option));

  const io::Sequence base(args.get("base"));
  std::vector<io::Sequence> targets;
  for (const auto& path : args.get_all("target")) targets.emplace_back(path);
  require_frame(base, frame_index);
  for (const auto& t : targets) require_frame(t, frame_index);

  // The frames each stage needs, counted from frame_index; the base's are shared by all targets.
  // HOTS needs them all.
  const std::size_t base_count = run_hots   ? base.size() - frame_index
                                 : run_jeep ? options.jeep.frames
                                            : 1;
  const bool quiet = args.has("quiet");
  const LoadedFrames base_frames = load_frames(base, frame_index, base_count);

  std::vector<io::PairResult> results;
  std::vector<FusedPart> fused{{points_of(base_frames.clouds.front()), Isometry3d::Identity()}};
  std::vector<ReportCloud> report{
      {base.name(), fused.front().points, Isometry3d::Identity(), Isometry3d::Identity()}};
  for (const auto& target : targets) {
    const std::size_t count = run_hots   ? target.size() - frame_index
                              : run_jeep ? covering_count(base, target, base_count)
                                         : 1;
    const LoadedFrames target_frames = load_frames(target, frame_index, count);
    CalibrateOptions pair_options = options;
    pair_options.frame_index = 0;  // the loaded frames start at frame_index
    if (!run_terra)
      pair_options.initial = parse_initial(args.get("initial"), base.name(), target.name());
    StageProgress progress(target.name(), quiet);
    pair_options.progress = [&progress](const std::string& stage, double f) { progress(stage, f); };
    auto run = [&] {
      return calibrate_pair(base_frames.clouds, base_frames.times, target_frames.clouds,
                            target_frames.times, pair_options);
    };
    const PairCalibration c = arena ? arena->execute(run) : run();
    io::PairResult r = to_pair_result(c, base.name(), target.name());
    if (r.stages.find("terra")) r.stages["terra"]["frame_index"] = frame_index;
    if (args.has("merged-cloud") || args.has("report")) {
      // Pictures show the calibrated frames only when they are worth showing; a failed target is
      // drawn where its guess put it, in both panels.
      const Isometry3d before = pair_options.initial.value_or(Isometry3d::Identity());
      const Isometry3d after = r.success ? r.T_base_target : before;
      fused.push_back({points_of(target_frames.clouds.front()), after});
      report.push_back({target.name(), fused.back().points, before, after});
    }
    results.push_back(std::move(r));
    print_summary(results.back());
  }

  if (args.has("output")) {
    if (format == "yaml")
      io::write_result_yaml(args.get("output"), results);
    else
      io::write_result_file(args.get("output"), results);
    std::printf("wrote %s\n", args.get("output").c_str());
  }
  if (args.has("merged-cloud")) {
    write_fused_cloud(args.get("merged-cloud"), fused);
    std::printf("wrote %s\n", args.get("merged-cloud").c_str());
  }
  if (args.has("report")) {
    write_calibration_report(args.get("report"), report);
    std::printf("wrote %s\n", args.get("report").c_str());
  }
  for (const auto& r : results)
    if (!r.success) return kExitFailed;
  return kExitOk;
}

}  // namespace ulc::app
