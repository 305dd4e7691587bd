// The definition of ulc::calibrate_pair on PointCloud<float> frames (pipeline/calibrate.hpp): the
// whole pipeline, compiled in the one file that includes this header. The CMake target
// ulc::calibrate is that file; a header-only user includes this header in exactly one of theirs.
#pragma once

#include "pipeline/calibrate.hpp"
#include "pipeline/pipeline.hpp"

namespace ulc {

PairCalibration calibrate_pair(const FloatFrames& frames_a, const std::vector<double>& times_a,
                               const FloatFrames& frames_b, const std::vector<double>& times_b,
                               const CalibrateOptions& options) {
  return calibrate_pair_in_place(frames_a, times_a, frames_b, times_b, options);
}

}  // namespace ulc
