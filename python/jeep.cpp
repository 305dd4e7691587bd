// ulc.jeep.run: JEEP on its own (jeep/jeep.hpp): the extrinsic refined jointly with the poses
// of the first K frame pairs, from a guess (TERRA's rotation, or any initial extrinsic).
#include "jeep/jeep.hpp"
#include "call_control.hpp"
#include "errors.hpp"
#include "frames.hpp"

namespace ulc::python {
namespace {

py::dict run(const py::handle& base, const py::handle& base_times, const py::handle& target,
             const py::handle& target_times, const py::handle& initial, std::size_t frames,
             std::size_t threads, const py::object& progress) {
  const FloatFrames a = frames_from_python(base, "ulc jeep.run: base");
  const std::vector<double> ta =
      times_from_python(base_times, a.size(), "ulc jeep.run: base_times");
  const FloatFrames b = frames_from_python(target, "ulc jeep.run: target");
  const std::vector<double> tb =
      times_from_python(target_times, b.size(), "ulc jeep.run: target_times");
  const Isometry3d guess = isometry_from_python(initial, "ulc jeep.run: initial");
  jeep::JeepOptions options;
  options.frames = frames;
  const CalibrateProgress hook = python_progress(progress);
  const odometry::ProgressFn round = [&hook](std::size_t done, std::size_t total) {
    hook("jeep", total ? static_cast<double>(done) / static_cast<double>(total) : 1.0);
  };
  const jeep::JeepResult r = without_gil([&] {
    return in_arena(threads, [&] { return jeep::run_jeep(a, ta, b, tb, guess, options, round); });
  });
  py::dict out;
  out["status"] = jeep::to_string(r.status);
  out["reason"] = std::string(r.reason);
  out["success"] = r.ok();
  out["T_base_target"] = array_from_isometry(r.extrinsic);
  out["rounds"] = r.rounds;
  out["frame_pairs"] = r.pairs.size();
  out["accepted"] = r.acceptance.accepted;
  out["overlap"] = r.acceptance.overlap;
  return out;
}

}  // namespace

void bind_jeep(py::module_& m) {
  py::module_ jeep = m.def_submodule("jeep", "JEEP: the extrinsic and the first poses, jointly");
  jeep.def("run", &run, py::arg("base"), py::arg("base_times"), py::arg("target"),
           py::arg("target_times"), py::arg("initial"), py::kw_only(),
           py::arg("frames") = jeep::JeepOptions{}.frames, py::arg("threads") = 0,
           py::arg("progress") = py::none(),
           "Refines the 4x4 guess `initial` (T_base_target) with the first `frames` frame pairs "
           "(lists of N x 3 or N x 4 arrays and their timestamps): {'status', 'reason', "
           "'success', 'T_base_target', 'rounds', 'frame_pairs', 'accepted', 'overlap'}.");
}

}  // namespace ulc::python
