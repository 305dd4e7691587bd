// The frame nearest an instant: the one lookup the stages that pair frames across LiDARs share
// (HOTS's cross links, the ground vote's base frame for each target frame).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace ulc {

/// The index, counted from `first`, of the entry of times[first, first + count) nearest t (the
/// earliest on ties); 0 when the range is empty. The times need not be sorted.
inline std::size_t nearest_time(const std::vector<double>& times, double t, std::size_t first = 0,
                                std::size_t count = std::numeric_limits<std::size_t>::max()) {
  if (first >= times.size()) return 0;
  const std::size_t n = std::min(count, times.size() - first);
  std::size_t best = 0;
  for (std::size_t k = 1; k < n; ++k)
    if (std::abs(times[first + k] - t) < std::abs(times[first + best] - t)) best = k;
  return best;
}

}  // namespace ulc
