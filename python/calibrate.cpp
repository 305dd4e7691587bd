// ulc.calibrate: a pair or a rig from numpy frames or from sources the command line reads (frame
// folders, cloud files, FILE:TOPIC of recordings), with `ulc calibrate`'s options as keyword
// arguments. Both paths share the command line's code (apps/ulc/rig_run.hpp): the same input
// gives the same result file.
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "array_frames.hpp"
#include "call_control.hpp"
#include "errors.hpp"
#include "frames.hpp"
#include "initial_extrinsic.hpp"
#include "pipeline/selection.hpp"
#include "results.hpp"
#include "rig_run.hpp"

namespace ulc::python {
namespace {

/// The keyword arguments that are not sources.
struct CalibrateKeywords {
  app::CalibrateChoices choices;
  py::object initial;  ///< None, text as --initial, a 4x4 array, or a list of them per target
  std::size_t frame_index = 0;
  std::size_t threads = 0;
  double budget_s = SelectionOptions{}.budget_s;  ///< paths only: as --budget
  bool route = true, cycles = true;
  app::InputOptions input;
  py::object names;     ///< None or one name per LiDAR, base first
  py::object progress;  ///< None or progress(stage, fraction)
};

/// One LiDAR as given: a source the command line reads, or frames and timestamps.
struct Source {
  py::object data;
  py::object times;
};

bool is_path(const py::handle& obj) {
  return py::isinstance<py::str>(obj) ||
         py::isinstance(obj, py::module_::import("os").attr("PathLike"));
}

std::string path_text(const py::handle& obj) {
  return py::str(py::module_::import("os").attr("fspath")(obj)).cast<std::string>();
}

std::vector<std::string> lidar_names(const CalibrateKeywords& k, std::size_t count) {
  std::vector<std::string> names;
  if (k.names.is_none()) return names;
  names = k.names.cast<std::vector<std::string>>();
  if (names.size() != count)
    raise_error("ulc calibrate: names: " + std::to_string(names.size()) + " names for " +
                std::to_string(count) + " LiDARs (base first)");
  return names;
}

/// The text of --initial, when `initial` is one (else nullopt).
std::optional<std::string> initial_text(const py::object& initial) {
  if (initial.is_none() || !py::isinstance<py::str>(initial)) return std::nullopt;
  return initial.cast<std::string>();
}

/// Target k's guess from a 4x4 array, or a list of them (one per target).
Isometry3d initial_matrix(const py::object& initial, std::size_t target, std::size_t targets) {
  const py::array a = py::module_::import("numpy").attr("asarray")(initial);
  if (a.ndim() == 3) {
    if (static_cast<std::size_t>(a.shape(0)) != targets)
      raise_error("ulc calibrate: initial: " + std::to_string(a.shape(0)) + " guesses for " +
                  std::to_string(targets) + " targets");
    return isometry_from_python(py::list(a)[target], "ulc calibrate: initial");
  }
  return isometry_from_python(a, "ulc calibrate: initial");
}

/// Frames given as arrays: each LiDAR's from frame_index on, read from the arrays when the
/// stages ask (array_frames.hpp), as the command line reads frames from disk.
struct ArrayRig {
  std::vector<std::unique_ptr<ArrayFrames>> frames;
  std::vector<std::vector<double>> times;
  std::vector<RigLidar<FrameSource>> lidars;
};

std::string default_name(std::size_t k, std::size_t count) {
  if (k == 0) return "base";
  return count == 2 ? "target" : "target_" + std::to_string(k);
}

void read_arrays(const std::vector<Source>& sources, const CalibrateKeywords& k, ArrayRig& rig) {
  const std::vector<std::string> names = lidar_names(k, sources.size());
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const std::string name = names.empty() ? default_name(i, sources.size()) : names[i];
    auto frames = std::make_unique<ArrayFrames>(sources[i].data, "ulc calibrate: " + name);
    std::vector<double> times =
        times_from_python(sources[i].times, frames->size(), "ulc calibrate: " + name + " times");
    if (k.frame_index >= frames->size())
      raise_error("ulc calibrate: --frame-index " + std::to_string(k.frame_index) +
                  " is past the last frame of " + name);
    frames->drop_front(k.frame_index);
    rig.frames.push_back(std::move(frames));
    rig.times.emplace_back(times.begin() + static_cast<std::ptrdiff_t>(k.frame_index), times.end());
  }
  for (std::size_t i = 0; i < sources.size(); ++i)
    rig.lidars.push_back({names.empty() ? default_name(i, sources.size()) : names[i],
                          rig.frames[i].get(), &rig.times[i], std::nullopt});
}

/// Every target's guess when the stages skip terra (k.choices.initial was checked for text).
void set_initials(std::vector<RigLidar<FrameSource>>& lidars, const CalibrateKeywords& k) {
  if (k.initial.is_none()) return;
  const std::optional<std::string> text = initial_text(k.initial);
  for (std::size_t i = 1; i < lidars.size(); ++i)
    lidars[i].initial = text ? app::parse_initial(*text, lidars[0].name, lidars[i].name)
                             : initial_matrix(k.initial, i - 1, lidars.size() - 1);
}

app::RigRequest path_request(const std::vector<Source>& sources, const CalibrateKeywords& k) {
  app::RigRequest r;
  const std::vector<std::string> names = lidar_names(k, sources.size());
  for (std::size_t i = 0; i < sources.size(); ++i) {
    if (!sources[i].times.is_none())
      raise_error("ulc calibrate: times are given with frames, not with a path (" +
                  path_text(sources[i].data) + ")");
    app::LidarSpec spec =
        app::parse_lidar_spec(path_text(sources[i].data), "calibrate", i ? "target" : "base");
    if (!names.empty()) spec.name = names[i];
    r.specs.push_back(std::move(spec));
  }
  r.input = k.input;
  r.frame_index = k.frame_index;
  r.budget_s = k.budget_s;
  r.threads = k.threads;
  if (const auto text = initial_text(k.initial)) r.initial = *text;
  return r;
}

RigOptions rig_options(const CalibrateOptions& options, const CalibrateKeywords& k,
                       std::size_t lidar_count) {
  RigOptions rig = app::rig_options(options, k.route, k.cycles, lidar_count);
  rig.pair.frame_index = 0;  // every LiDAR's frames start at frame_index
  rig.pair.progress = python_progress(k.progress);
  return rig;
}

RigResult run(const std::vector<RigLidar<FrameSource>>& lidars, const CalibrateOptions& options,
              const CalibrateKeywords& k) {
  const RigOptions rig = rig_options(options, k, lidars.size());
  const RigCalibration calibration =
      without_gil([&] { return app::run_rig(lidars, rig, k.threads); });
  return RigResult{app::rig_entries(calibration, k.frame_index)};
}

/// The same on sources read on demand, as `ulc calibrate` does (stages.selection when surveyed).
RigResult run(const app::LoadedRig& loaded, const CalibrateOptions& options,
              const CalibrateKeywords& k) {
  const RigOptions rig = rig_options(options, k, loaded.lidars.size());
  const RigCalibration calibration =
      without_gil([&] { return app::run_rig(loaded, rig, k.threads); });
  return RigResult{app::rig_entries(calibration, k.frame_index, loaded.selection, loaded.budget_s)};
}

RigResult calibrate_rig_sources(const std::vector<Source>& sources, CalibrateKeywords& k) {
  const bool paths = is_path(sources.front().data);
  for (const Source& s : sources)
    if (is_path(s.data) != paths)
      raise_error(
          "ulc calibrate: give every LiDAR as a path, or every LiDAR as frames (arrays), not a "
          "mix");
  const bool guess_is_text = k.initial.is_none() || initial_text(k.initial).has_value();
  if (!k.initial.is_none())
    k.choices.initial = guess_is_text ? *initial_text(k.initial) : "0 0 0 0 0 0";
  if (paths && !guess_is_text)
    raise_error(
        "ulc calibrate: initial: with paths, give it as --initial's text (six numbers "
        "or a result file)");
  return with_cli_errors("calibrate", [&] {
    const CalibrateOptions options = app::calibrate_options(k.choices);
    if (paths) {
      const app::LoadedRig loaded = app::load_rig(path_request(sources, k), options);
      return run(loaded, options, k);
    }
    ArrayRig rig;
    read_arrays(sources, k, rig);
    set_initials(rig.lidars, k);
    return run(rig.lidars, options, k);
  });
}

std::string stages_text(const py::object& stages) {
  if (py::isinstance<py::str>(stages)) return stages.cast<std::string>();
  std::string text;
  for (const auto& s : stages) text += (text.empty() ? "" : ",") + py::str(s).cast<std::string>();
  return text;
}

}  // namespace

namespace {

const char* const kCalibrateDoc =
    R"(Calibrates target LiDARs against a base, as `ulc calibrate` does.

A LiDAR is either a source the command line reads (a frame folder, a cloud file, FILE:TOPIC of a
.bag/.mcap/rosbag2 recording, optionally followed by =NAME), or its frames: a list of N x 3 or
N x 4 arrays (x y z [t], t in seconds from the frame's timestamp; float32 or float64, any strides;
Open3D clouds too) with one timestamp per frame in *_times (seconds, the LiDAR's own clock).
Arrays are not copied: each frame is read from its array when a stage asks for it, so they must
not change during the call.

target= calibrates a pair and returns a Result; targets=[...] (with target_times=[...]) a rig
and returns a RigResult. The other keywords mirror `ulc calibrate --help`: stages, initial
(text as --initial, or 4x4 arrays), frame_index, frames, synced_clocks, time_offset, threads,
route (not --no-route), cycles (not --no-cycles), start, duration, frame_time, budget (paths:
seconds HOTS calibrates on, a longer drive's best stretch chosen; 0: all), base_odometry (True as
--base-odometry: HOTS starts from the base's own odometry, run once for every target; False as
--joint-odometry; None: the pipeline chooses, as the command line does); names gives each
LiDAR's name (base first). progress(stage, fraction) is called between steps. Bad input raises
ulc.Error with the command line's message; Ctrl-C raises KeyboardInterrupt.)";

/// The sources in order, base first; target= (a pair) or targets= (a rig), not both.
std::vector<Source> sources_of(const py::object& base, const py::object& base_times,
                               const py::object& target, const py::object& target_times,
                               const py::object& targets) {
  if (target.is_none() == targets.is_none())
    raise_error("ulc calibrate: give target= (a pair) or targets= (a rig), one of them");
  std::vector<Source> sources{{base, base_times}};
  if (!target.is_none()) {
    sources.push_back({target, target_times});
    return sources;
  }
  const auto list = targets.cast<py::list>();
  if (list.size() == 0) raise_error("ulc calibrate: targets is empty");
  py::list times = target_times.is_none() ? py::list() : target_times.cast<py::list>();
  if (!target_times.is_none() && times.size() != list.size())
    raise_error("ulc calibrate: target_times: " + std::to_string(times.size()) +
                " lists of timestamps for " + std::to_string(list.size()) + " targets");
  for (std::size_t k = 0; k < list.size(); ++k)
    sources.push_back({list[k], times.empty() ? py::object(py::none()) : py::object(times[k])});
  return sources;
}

py::object calibrate(const py::object& base, const py::object& target, const py::object& targets,
                     const py::object& base_times, const py::object& target_times,
                     CalibrateKeywords k) {
  const std::vector<Source> sources = sources_of(base, base_times, target, target_times, targets);
  RigResult rig = calibrate_rig_sources(sources, k);
  if (!target.is_none()) return py::cast(Result{rig.document.results.front()});
  return py::cast(std::move(rig));
}

}  // namespace

void bind_calibrate(py::module_& m) {
  m.def(
      "calibrate",
      [](const py::object& base, const py::object& target, const py::object& targets,
         const py::object& base_times, const py::object& target_times, const py::object& stages,
         const py::object& initial, std::size_t frame_index, std::size_t frames, bool synced_clocks,
         std::optional<double> time_offset, std::size_t threads, bool route, bool cycles,
         std::optional<double> start, std::optional<double> duration, const std::string& frame_time,
         double budget, std::optional<bool> base_odometry, const py::object& names,
         const py::object& progress) {
        CalibrateKeywords k;
        k.choices.stages = stages_text(stages);
        k.choices.frames = frames;
        k.choices.synced_clocks = synced_clocks;
        k.choices.time_offset_s = time_offset;
        if (base_odometry)
          k.choices.odometry = *base_odometry ? HotsOdometry::base : HotsOdometry::joint;
        k.initial = initial;
        k.frame_index = frame_index;
        k.threads = threads;
        k.route = route;
        k.cycles = cycles;
        if (!(budget >= 0.0)) raise_error("ulc calibrate: budget must be 0 or more seconds");
        k.budget_s = budget;
        k.input = with_cli_errors("calibrate", [&] {
          return app::input_options(start, duration, frame_time, "calibrate");
        });
        k.names = names;
        k.progress = progress;
        return calibrate(base, target, targets, base_times, target_times, std::move(k));
      },
      kCalibrateDoc, py::arg("base"), py::arg("target") = py::none(), py::kw_only(),
      py::arg("targets") = py::none(), py::arg("base_times") = py::none(),
      py::arg("target_times") = py::none(), py::arg("stages") = "terra,jeep,hots",
      py::arg("initial") = py::none(), py::arg("frame_index") = 0,
      py::arg("frames") = jeep::JeepOptions{}.frames, py::arg("synced_clocks") = false,
      py::arg("time_offset") = py::none(), py::arg("threads") = 0, py::arg("route") = true,
      py::arg("cycles") = true, py::arg("start") = py::none(), py::arg("duration") = py::none(),
      py::arg("frame_time") = "header", py::arg("budget") = SelectionOptions{}.budget_s,
      py::arg("base_odometry") = py::none(), py::arg("names") = py::none(),
      py::arg("progress") = py::none());
}

}  // namespace ulc::python
