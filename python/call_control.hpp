// How a long C++ call behaves from Python: the GIL is released while it works, so other Python
// threads run; the pipeline's progress hook (CalibrateOptions::progress, called on the calling
// thread between steps: every TERRA search stage, JEEP round, odometry frame pair, HOTS phase,
// and within HOTS's phases every few frames, windows or cross links and each sub-step of its
// whole-sequence step) takes the GIL back briefly to
//   - check for signals (PyErr_CheckSignals): Ctrl-C raises KeyboardInterrupt there, and the
//     C++ call unwinds at once (the exception leaves through the pipeline, which holds no
//     resource it does not release on unwinding);
//   - call the user's progress(stage, fraction), whose exceptions stop the call the same way.
// Ctrl-C is therefore noticed at the next step: within a fraction of a second in TERRA, JEEP and
// the odometry, within seconds in HOTS (docs/BENCHMARKS.md, "Progress and Ctrl-C", measures the
// longest wait: 2.7 s on the 60 s drive at 2 threads).
#pragma once

#include <tbb/task_arena.h>

#include <optional>
#include <utility>

#include "bindings.hpp"
#include "pipeline/options.hpp"

namespace ulc::python {

/// The progress hook of one call: signals, then the user's callable (None: none).
CalibrateProgress python_progress(py::object progress);

/// Runs `f` with the GIL released; Python exceptions raised by the hook come back out.
template <class F>
auto without_gil(F&& f) -> decltype(f()) {
  py::gil_scoped_release release;
  return std::forward<F>(f)();
}

/// Runs `f` in a task arena of `threads` workers (0: TBB's default, all cores).
template <class F>
auto in_arena(std::size_t threads, F&& f) -> decltype(f()) {
  if (threads == 0) return std::forward<F>(f)();
  tbb::task_arena arena(static_cast<int>(threads));
  return arena.execute(std::forward<F>(f));
}

}  // namespace ulc::python
