// The calibration's result as Python sees it: the result file's entries (io::PairResult,
// io::CycleResult), written by the same writers as `ulc calibrate --output` (to_json(),
// to_yaml() give the file's bytes for the same result).
#pragma once

#include "bindings.hpp"
#include "ulc/io/result_file.hpp"

namespace ulc::python {

/// One target's calibration (ulc.Result).
struct Result {
  io::PairResult entry;
};

/// A rig: every target's calibration and the cycles between targets (ulc.RigResult).
struct RigResult {
  io::ResultDocument document;
};

}  // namespace ulc::python
