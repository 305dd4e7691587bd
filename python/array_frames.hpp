// One LiDAR's numpy frames as a ulc::FrameSource: the pipeline reads each frame from the caller's
// array when a stage asks for it (frames.hpp, read_frame), as `ulc calibrate` reads frames from
// disk, so ulc.calibrate on arrays holds no copy of the drive: its points are in memory once, in
// the caller's arrays (docs/BENCHMARKS.md, "Python overhead": peak memory).
//
// Conventions:
//   - Built with the GIL held: every frame is checked then (frames.hpp, array_frame) and a
//     reference to its array kept, so the buffers live as long as the source; load() reads only
//     those buffers and runs on any thread without the GIL.
//   - The arrays must not be written to while a call reads them.
//   - Destroyed with the GIL held (it releases the arrays).
#pragma once

#include <string>
#include <vector>

#include "frames.hpp"
#include "ulc/core/frame_source.hpp"

namespace ulc::python {

class ArrayFrames : public FrameSource {
 public:
  /// A list of N x 3 / N x 4 arrays, or one array alone; ulc.Error naming `what`.
  ArrayFrames(const py::handle& frames, const std::string& what)
      : frames_(array_frames(frames, what)) {}

  std::size_t size() const override { return frames_.size(); }
  PointCloud<float> load(std::size_t i) const override { return read_frame(frames_[i]); }

  /// Drops the first `count` frames (the calibration starts after them).
  void drop_front(std::size_t count) {
    frames_.erase(frames_.begin(), frames_.begin() + static_cast<std::ptrdiff_t>(count));
  }

 private:
  std::vector<ArrayFrame> frames_;
};

}  // namespace ulc::python
