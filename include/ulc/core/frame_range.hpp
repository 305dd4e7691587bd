// A read-only view of the frames of a sequence from one index on, so that a stage can start at
// a caller's frame without copying clouds. It offers what the stages use of a frame container:
// size() and operator[] returning the container's own element reference.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace ulc {

template <class Frames>
class FrameRange {
 public:
  /// Frames first, first + 1, ... of `frames` (empty when first is past the end).
  FrameRange(const Frames& frames, std::size_t first)
      : frames_(&frames), first_(std::min<std::size_t>(first, frames.size())) {}

  std::size_t size() const { return frames_->size() - first_; }
  decltype(auto) operator[](std::size_t i) const { return (*frames_)[first_ + i]; }
  const Frames& container() const { return *frames_; }

 private:
  const Frames* frames_;
  std::size_t first_;
};

/// times[first..] (empty when first is past the end).
inline std::vector<double> times_from(const std::vector<double>& times, std::size_t first) {
  return first >= times.size()
             ? std::vector<double>{}
             : std::vector<double>(times.begin() + static_cast<long>(first), times.end());
}

}  // namespace ulc
