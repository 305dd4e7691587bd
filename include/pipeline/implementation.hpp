// The definition of ulc::calibrate_pair on PointCloud<float> frames (pipeline/calibrate.hpp): the
// whole pipeline, compiled in the one file that includes this header. The CMake target
// ulc::calibrate is that file; a header-only user includes this header in exactly one of theirs.
#pragma once

#include "pipeline/calibrate.hpp"
#include "pipeline/pipeline.hpp"
#include "pipeline/point_times.hpp"

namespace ulc {

PairCalibration calibrate_pair(const FloatFrames& frames_a, const std::vector<double>& times_a,
                               const FloatFrames& frames_b, const std::vector<double>& times_b,
                               const CalibrateOptions& options) {
  // A LiDAR without per-point times gets them from azimuth when it spins (point_times.hpp).
  TimedFrames a, b;
  fill_point_times(frames_a, times_a, options.frame_index, a);
  fill_point_times(frames_b, times_b, options.frame_index, b);
  PairCalibration r = calibrate_pair_in_place(*a.frames, times_a, *b.frames, times_b, options);
  report_point_times(a, r.point_times_base);
  report_point_times(b, r.point_times_target);
  return r;
}

PairCalibration calibrate_pair(const FrameSource& frames_a, const std::vector<double>& times_a,
                               const FrameSource& frames_b, const std::vector<double>& times_b,
                               const CalibrateOptions& options) {
  const TimedSource a(frames_a, times_a, options.frame_index);
  const TimedSource b(frames_b, times_b, options.frame_index);
  PairCalibration r = calibrate_pair_in_place(a, times_a, b, times_b, options);
  report_point_times(a.summary(), r.point_times_base);
  report_point_times(b.summary(), r.point_times_target);
  return r;
}

}  // namespace ulc
