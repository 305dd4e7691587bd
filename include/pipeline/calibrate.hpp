// ulc::calibrate_pair: the extrinsic T_base_target of a target LiDAR b against a base LiDAR a,
// from each LiDAR's frames and timestamps, with no initial guess (TERRA, JEEP, odometry, HOTS;
// the conventions are those of pipeline/pipeline.hpp, which runs the stages).
//
// This header is light: it includes the options and result types, never the algorithms, so a
// file that calls the pipeline compiles in seconds (docs/BENCHMARKS.md, "Compile time"). The
// pipeline itself runs on ulc::PointCloud<float> frames and is compiled once:
//   - link the CMake target ulc::calibrate (a static library of that one file), or
//   - header-only: include pipeline/implementation.hpp in exactly one file of your program.
// Frames of any other type (your own point struct, through ulc::traits) are adapted once at the
// entry: points as float, with the per-point times and intensities the type has. To read them in
// place instead, call calibrate_pair_in_place (pipeline/pipeline.hpp): every stage is then
// compiled for your type, which takes minutes per file.
#pragma once

#include <type_traits>
#include <vector>

#include "pipeline/options.hpp"
#include "pipeline/pair_calibration.hpp"
#include "ulc/core/frame_source.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/point_traits.hpp"

namespace ulc {

/// The frames the compiled pipeline reads.
using FloatFrames = std::vector<PointCloud<float>>;

/// The pipeline on PointCloud<float> frames (defined in pipeline/implementation.hpp).
PairCalibration calibrate_pair(const FloatFrames& frames_a, const std::vector<double>& times_a,
                               const FloatFrames& frames_b, const std::vector<double>& times_b,
                               const CalibrateOptions& options = {});

/// The pipeline on frames read on demand (ulc/core/frame_source.hpp): no stage holds a whole
/// drive's raw frames. The result is the same as on the same frames held in memory. A frame that
/// could not be read reaches the stages empty: check each source's error() after the call.
PairCalibration calibrate_pair(const FrameSource& frames_a, const std::vector<double>& times_a,
                               const FrameSource& frames_b, const std::vector<double>& times_b,
                               const CalibrateOptions& options = {});

/// Any traits cloud as a PointCloud<float>: points, and per-point times and intensities when the
/// cloud has them.
template <class Cloud>
PointCloud<float> to_float_cloud(const Cloud& cloud) {
  ULC_REQUIRE_CLOUD(Cloud);
  PointCloud<float> out;
  const std::size_t n = traits::size(cloud);
  out.points.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    out.points[i] = traits::point(cloud, i).template cast<float>();
  if (traits::has_time(cloud)) {
    out.times.resize(n);
    for (std::size_t i = 0; i < n; ++i) out.times[i] = traits::time(cloud, i);
  }
  if (traits::has_intensity(cloud)) {
    out.intensities.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      out.intensities[i] = static_cast<float>(traits::intensity(cloud, i));
  }
  return out;
}

namespace calibrate_entry {

/// `frames` itself when it already is FloatFrames, else its copy in `storage`.
template <class Frames>
const FloatFrames& float_frames(const Frames& frames, FloatFrames& storage) {
  if constexpr (std::is_same_v<Frames, FloatFrames>) {
    return frames;
  } else {
    storage.clear();
    storage.reserve(frames.size());
    for (const auto& cloud : frames) storage.push_back(to_float_cloud(cloud));
    return storage;
  }
}

}  // namespace calibrate_entry

/// The pipeline on frames of any traits cloud type (random-access containers of clouds, one
/// timestamp per frame), adapted once to PointCloud<float>.
template <class FramesA, class FramesB,
          class = std::enable_if_t<!std::is_base_of_v<FrameSource, FramesA> &&
                                   !std::is_base_of_v<FrameSource, FramesB>>>
PairCalibration calibrate_pair(const FramesA& frames_a, const std::vector<double>& times_a,
                               const FramesB& frames_b, const std::vector<double>& times_b,
                               const CalibrateOptions& options = {}) {
  FloatFrames storage_a, storage_b;
  return calibrate_pair(calibrate_entry::float_frames(frames_a, storage_a), times_a,
                        calibrate_entry::float_frames(frames_b, storage_b), times_b, options);
}

}  // namespace ulc
