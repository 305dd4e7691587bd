// ulc::FrameSource: one LiDAR's frames read on demand, so that no stage holds a whole drive.
//
// The stages take any random-access container of clouds (size() and operator[]); a FrameSource
// is one whose operator[] reads frame i when asked and hands it over by value. The odometry
// reads each frame once, in order, and keeps only its bounded local map; HOTS reads each frame
// once more, deskews and thins it and keeps the thinned points. A drive's raw frames are then
// never all in memory: memory grows with what the stages keep, not with the raw clouds
// (docs/BENCHMARKS.md, "Long drives").
//
// Conventions:
//   - load(i) is called from any thread, concurrently; it returns frame i with per-point times
//     relative to the frame's timestamp (as the stages expect).
//   - A frame that cannot be read comes back empty, and error() then names the file and the
//     problem (the first one met): the pipeline does not throw, the caller checks error() after
//     the calibration and refuses its result.
//   - FramesView wraps frames already in memory (tests, callers that hold their frames).
#pragma once

#include <cstddef>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "ulc/core/point_cloud.hpp"

namespace ulc {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual std::size_t size() const = 0;
  /// Frame i (see the conventions); empty when it could not be read.
  virtual PointCloud<float> load(std::size_t i) const = 0;
  PointCloud<float> operator[](std::size_t i) const { return load(i); }

  /// The first read failure ("FILE: problem"), empty when every read succeeded.
  std::string error() const {
    const std::lock_guard<std::mutex> lock(error_mutex_);
    return error_;
  }

 protected:
  /// Records a read failure (the first one is kept).
  void fail(std::string why) const {
    const std::lock_guard<std::mutex> lock(error_mutex_);
    if (error_.empty()) error_ = std::move(why);
  }

 private:
  mutable std::mutex error_mutex_;
  mutable std::string error_;
};

/// Frames held in memory, as a FrameSource (copies each frame it hands over).
class FramesView : public FrameSource {
 public:
  explicit FramesView(const std::vector<PointCloud<float>>& frames) : frames_(&frames) {}
  std::size_t size() const override { return frames_->size(); }
  PointCloud<float> load(std::size_t i) const override { return (*frames_)[i]; }

 private:
  const std::vector<PointCloud<float>>* frames_;
};

}  // namespace ulc
