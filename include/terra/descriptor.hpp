// TERRA descriptor: a cloud seen from its origin, as one range per Fibonacci-lattice cell.
//
// Conventions this header owns:
//   - Each point p (in the LiDAR's frame, or a local map's frame whose origin is the LiDAR)
//     with min_range <= |p| (and |p| <= max_range) is projected onto the unit sphere, p / |p|,
//     and assigned to its nearest lattice point. A cell keeps the smallest range among its
//     points: the paper's choice, what the LiDAR saw first along that direction, so a merged
//     local map behaves like a single frame (nearer surfaces occlude farther ones).
//   - An empty cell holds 0. Every filled cell holds a range >= min_range > 0, so "> d1" in the
//     distance (distance.hpp) never takes an empty cell for a far one.
//   - Points closer than min_range (the vehicle body, 0.5 m by default) or with a non-finite
//     coordinate are ignored and counted.
//   - Ranges are computed in double and stored in the cloud's scalar S; the minimum of the
//     rounded values is the rounded minimum, so float and double descriptors agree to rounding.
//   - Deterministic: per-point lattice cells are found in parallel, the minimum is taken in
//     point order afterwards (and a minimum does not depend on order anyway).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "terra/lattice.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace terra {

struct DescriptorOptions {
  double min_range = 0.5;  ///< metres; nearer points are ignored (the vehicle itself)
  double max_range = std::numeric_limits<double>::infinity();  ///< farther points ignored
};

template <typename S>
struct Descriptor {
  std::vector<S> range;            ///< one per lattice point; 0 = no point in the cell
  std::size_t points_used = 0;     ///< points that filled a cell
  std::size_t points_ignored = 0;  ///< outside [min_range, max_range]
  std::size_t points_invalid = 0;  ///< a NaN or infinite coordinate

  std::size_t size() const { return range.size(); }
  std::size_t filled_cells() const {
    return static_cast<std::size_t>(
        std::count_if(range.begin(), range.end(), [](S r) { return r > S(0); }));
  }
  /// Cells whose range exceeds d (the cells eq:mask can use with d1 = d).
  std::size_t cells_beyond(double d) const {
    return static_cast<std::size_t>(
        std::count_if(range.begin(), range.end(), [d](S r) { return static_cast<double>(r) > d; }));
  }
};

/// Builds the descriptor of `cloud` on `lattice` (terra::Lattice, or any lookup with size()
/// and nearest(const Vec3d&), such as KdTreeLookup). An empty lattice gives an empty
/// descriptor.
template <class Cloud, class Lookup>
Descriptor<ulc::traits::scalar_t<Cloud>> make_descriptor(const Lookup& lattice, const Cloud& cloud,
                                                         const DescriptorOptions& options = {}) {
  using S = ulc::traits::scalar_t<Cloud>;
  constexpr std::uint32_t kSkipNear = std::numeric_limits<std::uint32_t>::max();
  constexpr std::uint32_t kSkipInvalid = kSkipNear - 1;
  Descriptor<S> out;
  const std::size_t n = lattice.size();
  if (n == 0) return out;
  out.range.assign(n, S(0));
  const std::size_t count = ulc::traits::size(cloud);
  std::vector<std::uint32_t> cell(count);
  std::vector<double> range(count);
  constexpr std::size_t kGrain = 4096;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, count, kGrain),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
          const ulc::Vec3d p = ulc::traits::point(cloud, i).template cast<double>();
          const double d = p.norm();
          range[i] = d;
          if (!std::isfinite(d)) {
            cell[i] = kSkipInvalid;
          } else if (!(d >= options.min_range && d <= options.max_range) || d == 0.0) {
            cell[i] = kSkipNear;
          } else {
            cell[i] = lattice.nearest(p / d);
          }
        }
      });
  for (std::size_t i = 0; i < count; ++i) {
    if (cell[i] == kSkipInvalid) {
      ++out.points_invalid;
    } else if (cell[i] == kSkipNear) {
      ++out.points_ignored;
    } else {
      S& slot = out.range[cell[i]];
      const S r = static_cast<S>(range[i]);
      if (slot == S(0) || r < slot) slot = r;
      ++out.points_used;
    }
  }
  return out;
}

}  // namespace terra
