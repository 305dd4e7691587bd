// ulc.simulate: a rig of the simulator (ulc/sim, what `ulc simulate` runs) with exact ground
// truth, held in memory so that a notebook can calibrate it at once; ulc.scenarios lists them.
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "call_control.hpp"
#include "errors.hpp"
#include "frames.hpp"
#include "ulc/sim/scenario.hpp"
#include "ulc/sim/simulate.hpp"

namespace ulc::python {
namespace {

py::dict lidar_dict(const sim::LidarRecording& l) {
  py::list frames;
  for (const auto& cloud : l.frames) frames.append(array_from_cloud(cloud));
  py::dict d;
  d["name"] = l.name;
  d["model"] = l.model;
  d["T_vehicle_lidar"] = array_from_isometry(l.T_vehicle_lidar);
  d["rate_hz"] = l.rate_hz;
  d["clock_offset_s"] = l.clock_offset_s;
  d["times"] =
      py::array_t<double>(static_cast<py::ssize_t>(l.timestamps.size()), l.timestamps.data());
  d["frames"] = frames;
  return d;
}

py::dict truth_dict(const sim::PairTruth& p) {
  py::dict d;
  d["base"] = p.base;
  d["target"] = p.target;
  d["T_base_target"] = array_from_isometry(p.T_base_target);
  d["time_offset_s"] = p.time_offset_s;
  return d;
}

py::dict dataset_dict(const sim::Dataset& d) {
  py::list lidars, truth;
  for (const auto& l : d.lidars) lidars.append(lidar_dict(l));
  for (const auto& p : d.pairs) truth.append(truth_dict(p));
  py::dict out;
  out["scenario"] = d.scenario;
  out["seed"] = d.seed;
  out["seconds"] = d.seconds;
  out["lidars"] = lidars;
  out["truth"] = truth;
  return out;
}

sim::ScenarioSpec named_scenario(const std::string& name, std::optional<double> steering_ramp) {
  std::optional<sim::ScenarioSpec> spec = sim::scenario(name);
  if (!spec) raise_error("ulc simulate: unknown scenario '" + name + "' (see ulc.scenarios())");
  if (steering_ramp) {
    if (!(*steering_ramp >= 0.0 && *steering_ramp <= 50.0))
      raise_error("ulc simulate: option '--steering-ramp' must be in [0, 50] m");
    spec->motion.steering_ramp_m = *steering_ramp;
  }
  return *spec;
}

py::dict simulate(const std::string& scenario, double seconds, std::uint64_t seed,
                  std::optional<double> rate, std::optional<double> time_offset,
                  std::optional<double> steering_ramp, unsigned decimation,
                  const py::object& progress) {
  const sim::ScenarioSpec spec = named_scenario(scenario, steering_ramp);
  // Recording starts 1 s into the drive (sim::kRecordingStart): own-clock times stay positive.
  if (time_offset && !(std::fabs(*time_offset) <= 1.0))
    raise_error("ulc simulate: option '--time-offset' must be within [-1, 1] s");
  sim::SimulationOptions options;
  options.seconds = seconds;
  options.seed = seed;
  options.rate_hz = rate;
  options.target_clock_offset_s = time_offset;
  options.decimation = decimation;
  const CalibrateProgress hook = python_progress(progress);
  const sim::SimulationResult result = without_gil([&] {
    return sim::simulate(spec, options, {}, [&hook](std::size_t done, std::size_t total) {
      hook("simulate", static_cast<double>(done) / static_cast<double>(total));
    });
  });
  if (!result.ok()) raise_error("ulc simulate: " + result.reason);
  return dataset_dict(result.dataset);
}

py::list scenarios() {
  py::list out;
  for (const auto& name : sim::scenario_names())
    out.append(py::make_tuple(name, sim::scenario(name)->description));
  return out;
}

}  // namespace

void bind_simulate(py::module_& m) {
  m.def("simulate", &simulate, py::arg("scenario") = "64-horizon", py::kw_only(),
        py::arg("seconds") = 20.0, py::arg("seed") = 1, py::arg("rate") = py::none(),
        py::arg("time_offset") = py::none(), py::arg("steering_ramp") = py::none(),
        py::arg("decimation") = 1, py::arg("progress") = py::none(),
        "Simulates a rig driving through a scene (`ulc simulate`, held in memory): {'scenario', "
        "'seed', 'seconds', 'lidars': [{'name', 'model', 'T_vehicle_lidar', 'rate_hz', "
        "'clock_offset_s', 'times', 'frames': [N x 4 arrays: x y z t]}], 'truth': [{'base', "
        "'target', 'T_base_target', 'time_offset_s'}]}. decimation keeps every n-th ray column "
        "(lighter frames). Rate and time_offset as `ulc simulate --rate --time-offset`.");
  m.def("scenarios", &scenarios, "The simulator's scenarios: [(name, description), ...].");
}

}  // namespace ulc::python
