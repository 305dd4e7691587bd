// DecodedCloud: the format-independent result of every reader, before it is poured into the
// caller's cloud type through ulc::traits.
//
// Everything is double so nothing is lost between the file and the caller (absolute Unix times
// in particular, which a float cannot hold to better than minutes). Points with a non-finite
// coordinate never enter a DecodedCloud; DecodedBuilder counts them.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <utility>
#include <vector>

#include "ulc/core/point_traits.hpp"
#include "ulc/io/read_stats.hpp"

namespace ulc::io {

struct DecodedCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> intensities;  ///< empty or one per point
  std::vector<double> times;        ///< seconds, empty or one per point

  std::size_t size() const { return points.size(); }
  bool has_intensities() const { return !intensities.empty(); }
  bool has_times() const { return !times.empty(); }
};

/// Collects points one at a time, dropping (and counting) those with a NaN / Inf coordinate.
class DecodedBuilder {
 public:
  /// `expected` must already be bounded by the file size (it is only a reservation).
  DecodedBuilder(std::size_t expected, bool with_intensity, bool with_time)
      : with_intensity_(with_intensity), with_time_(with_time) {
    cloud_.points.reserve(expected);
    if (with_intensity_) cloud_.intensities.reserve(expected);
    if (with_time_) cloud_.times.reserve(expected);
  }

  void add(double x, double y, double z, double intensity, double time) {
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      ++dropped_;
      return;
    }
    cloud_.points.emplace_back(x, y, z);
    if (with_intensity_) cloud_.intensities.push_back(intensity);
    if (with_time_) cloud_.times.push_back(time);
  }

  DecodedCloud finish(ReadStats& stats) {
    stats.points_read = cloud_.points.size();
    stats.points_dropped_nonfinite = dropped_;
    // A cloud whose every point was dropped must not claim per-point fields.
    if (cloud_.points.empty()) {
      cloud_.intensities.clear();
      cloud_.times.clear();
    }
    return std::move(cloud_);
  }

 private:
  DecodedCloud cloud_;
  bool with_intensity_;
  bool with_time_;
  std::size_t dropped_ = 0;
};

/// Pours a DecodedCloud into any writable cloud type. Fields the type cannot hold are skipped.
template <typename Cloud>
Cloud to_cloud(const DecodedCloud& decoded) {
  ULC_REQUIRE_WRITABLE_CLOUD(Cloud);
  using S = traits::scalar_t<Cloud>;
  Cloud cloud{};
  const std::size_t n = decoded.size();
  traits::resize(cloud, n);
  for (std::size_t i = 0; i < n; ++i) traits::set_point(cloud, i, decoded.points[i].cast<S>());
  if constexpr (traits::can_store_intensity_v<Cloud>) {
    if (decoded.has_intensities())
      for (std::size_t i = 0; i < n; ++i)
        traits::set_intensity(cloud, i, static_cast<S>(decoded.intensities[i]));
  }
  if constexpr (traits::can_store_time_v<Cloud>) {
    if (decoded.has_times())
      for (std::size_t i = 0; i < n; ++i) traits::set_time(cloud, i, decoded.times[i]);
  }
  return cloud;
}

}  // namespace ulc::io
