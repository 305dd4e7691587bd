// The elevation gap between a spinning LiDAR's rings, read off one raw frame: what the ground
// vote (ground_vote.hpp) fills between a sparse base's rings. Not in the paper (issue 34).
//
// Conventions this header owns:
//   - Elevations: atan2(z, hypot(x, y)) of the frame's finite points at least min_range from
//     the sensor, in the sensor's frame (a raw frame: deskewing moves near points off their
//     ring), binned in bin_deg.
//   - Rings: runs of consecutive bins holding at least min_bin_points points; a ring's
//     elevation is its run's centre.
//   - The gap: the median spacing of consecutive rings; 0 when there are fewer than min_rings
//     (a non-repetitive scan's elevations fill one run, or the frame is too small to tell).
//   - Nothing here throws or prints; the bins are bounded by the elevations' range (180 deg).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "ulc/core/angles.hpp"
#include "ulc/core/median.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace terra {

struct RingGapOptions {
  double bin_deg = 0.05;   ///< finer than any spinning LiDAR's ring spacing (0.1 deg and up)
  double min_range = 5.0;  ///< m
  std::size_t min_bin_points = 2;
  std::size_t min_rings = 4;
};

namespace ring_gap_detail {

/// Points per elevation bin, from -90 deg.
template <class Cloud>
std::vector<std::size_t> elevation_histogram(const Cloud& frame, const RingGapOptions& o) {
  std::vector<std::size_t> bins(static_cast<std::size_t>(std::ceil(180.0 / o.bin_deg)) + 1, 0);
  for (std::size_t i = 0; i < ulc::traits::size(frame); ++i) {
    const ulc::Vec3d p = ulc::traits::point(frame, i).template cast<double>();
    if (!p.allFinite() || p.norm() < o.min_range) continue;
    const double elevation = std::atan2(p.z(), std::hypot(p.x(), p.y())) * ulc::kDegPerRad;
    const double k = std::floor((elevation + 90.0) / o.bin_deg);
    if (k >= 0.0 && k < double(bins.size())) ++bins[static_cast<std::size_t>(k)];
  }
  return bins;
}

/// The centres (in bins) of the runs of bins holding at least min_bin_points.
inline std::vector<double> ring_centres(const std::vector<std::size_t>& bins,
                                        std::size_t min_bin_points) {
  std::vector<double> centres;
  std::size_t k = 0;
  while (k < bins.size()) {
    if (bins[k] < min_bin_points) {
      ++k;
      continue;
    }
    const std::size_t start = k;
    while (k < bins.size() && bins[k] >= min_bin_points) ++k;
    centres.push_back(0.5 * double(start + k - 1));
  }
  return centres;
}

}  // namespace ring_gap_detail

/// The median elevation spacing of the frame's rings in degrees (see the conventions).
template <class Cloud>
double ring_gap_deg(const Cloud& frame, const RingGapOptions& o = {}) {
  using namespace ring_gap_detail;
  if (!(o.bin_deg > 0.01 && o.bin_deg < 180.0)) return 0.0;
  const std::vector<double> rings =
      ring_centres(elevation_histogram(frame, o), std::max<std::size_t>(o.min_bin_points, 1));
  if (rings.size() < std::max<std::size_t>(o.min_rings, 2)) return 0.0;
  return ulc::median_step(rings) * o.bin_deg;
}

}  // namespace terra
