// Frames read on demand (ulc/core/frame_source.hpp): calibrate_pair on a FrameSource gives the
// bits it gives on the same frames in memory, HOTS included, and frames without per-point times
// are timed from azimuth (and counted) as they are read; a source that fails to read a frame says
// which.
#include <atomic>
#include <catch2/catch.hpp>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "calibrate_test_util.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/map_terra.hpp"
#include "ulc/core/frame_source.hpp"

using namespace calibrate_test;
using ulc::Stage;

namespace {

/// Frames in memory, counting the reads; frame `broken` (if any) cannot be read.
class CountingSource : public ulc::FrameSource {
 public:
  explicit CountingSource(const SimFrames& frames,
                          std::size_t broken = std::numeric_limits<std::size_t>::max())
      : frames_(frames), broken_(broken) {}
  std::size_t size() const override { return frames_.size(); }
  ulc::PointCloud<float> load(std::size_t i) const override {
    ++reads_;
    if (i != broken_) return frames_[i];
    fail("frame " + std::to_string(i) + ".pcd: truncated binary data");
    return {};
  }
  std::size_t reads() const { return reads_; }

 private:
  const SimFrames& frames_;
  std::size_t broken_;
  mutable std::atomic<std::size_t> reads_{0};
};

bool same_covariance(const ulc::Mat6d& a, const ulc::Mat6d& b) {
  return std::memcmp(a.data(), b.data(), 36 * sizeof(double)) == 0;
}

}  // namespace

TEST_CASE("calibrate_pair on frames read on demand gives the bits of frames in memory",
          "[calibrate][frame_source]") {
  const auto& d = drive_64_32_hots();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  ulc::CalibrateOptions o;  // terra, jeep, hots
  o.time_offset_s = 0.0;
  const auto held = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
  const CountingSource source_a(a.frames), source_b(b.frames);
  const auto read = ulc::calibrate_pair(source_a, a.timestamps, source_b, b.timestamps, o);
  INFO(ulc::to_string(read.status) << ": " << read.reason);
  REQUIRE(held.success);
  REQUIRE(read.success);
  CHECK(same_bits(held.T_base_target, read.T_base_target));
  REQUIRE(held.covariance_6x6);
  REQUIRE(read.covariance_6x6);
  CHECK(same_covariance(*held.covariance_6x6, *read.covariance_6x6));
  REQUIRE(read.hots);
  CHECK(read.hots->frames_base == a.frames.size());
  // Read, not held: the odometry and HOTS read each frame, JEEP and TERRA a few of them again
  // (TERRA's local maps read their window's frames twice: the odometry, then the stack).
  const std::size_t window =
      ulc::map_terra_detail::window_frames(a.timestamps, 0, o.tuning.terra_source.maps);
  CHECK(source_a.reads() >= 2 * a.frames.size());
  CHECK(source_a.reads() <= 4 * a.frames.size() + 2 * window);
  CHECK(source_a.error().empty());
}

TEST_CASE("frames read on demand without point times are timed from azimuth, and counted",
          "[calibrate][frame_source]") {
  auto d = simulate_64_32(1.0, 2, 4);
  for (auto& f : d.lidars.at(1).frames) f.times.clear();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  ulc::CalibrateOptions o;
  o.stages = {Stage::terra, Stage::jeep};
  o.time_offset_s = 0.0;
  const auto held = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
  const ulc::FramesView view_a(a.frames), view_b(b.frames);
  const auto read = ulc::calibrate_pair(view_a, a.timestamps, view_b, b.timestamps, o);
  INFO(ulc::to_string(read.status) << ": " << read.reason);
  CHECK(read.point_times_base.source == ulc::PointTimeSource::per_point);
  CHECK(read.point_times_target.source == ulc::PointTimeSource::synthesised_from_azimuth);
  CHECK(read.point_times_target.frames_without > 0);  // the frames JEEP read, not all of them
  CHECK(read.point_times_target.frames_without <= b.frames.size());
  CHECK(read.status == held.status);
  CHECK(same_bits(held.T_base_target, read.T_base_target));
}

TEST_CASE("a frame that cannot be read is named by its source", "[calibrate][frame_source]") {
  const auto& d = drive_64_32_hots();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  ulc::CalibrateOptions o;
  o.time_offset_s = 0.0;
  const CountingSource source_a(a.frames), source_b(b.frames, 12);
  (void)ulc::calibrate_pair(source_a, a.timestamps, source_b, b.timestamps, o);
  CHECK(source_a.error().empty());
  CHECK(source_b.error() == "frame 12.pcd: truncated binary data");
}
