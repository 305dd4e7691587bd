// SpooledFrames: frames copied once into an unnamed temporary file and read back on demand, for
// inputs that can only be read in order (a topic of a recording): the stages read frames in
// any order and from several threads, and holding a drive's frames would take its whole size
// in memory. The file lives in TMPDIR (else /tmp) and is gone when the object is, or the
// process ends; it takes about 20 bytes per point (points, times and intensities as stored).
#pragma once

#include <cstddef>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ulc/core/frame_source.hpp"

namespace ulc::app {

class SpooledFrames : public FrameSource {
 public:
  /// An empty spool; `what` names the input in messages. Throws io::IoError when no temporary
  /// file can be made.
  explicit SpooledFrames(std::string what);

  /// Appends a frame (throws io::IoError when the disk is full).
  void append(const PointCloud<float>& cloud);

  std::size_t size() const override { return frames_.size(); }
  PointCloud<float> load(std::size_t i) const override;

 private:
  struct Entry {
    long offset = 0;
    std::size_t points = 0;
    bool times = false, intensities = false;
  };
  std::string what_;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_;
  std::vector<Entry> frames_;
  long end_ = 0;
};

}  // namespace ulc::app
