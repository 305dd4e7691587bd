// Pairing the frames of a base LiDAR a and a target LiDAR b by timestamp.
//
// Conventions this header owns:
//   - Timestamps are seconds in each LiDAR's own clock (docs/design.md); b's are brought to a's
//     clock with t_base = t_target + time_offset_s.
//   - Each a frame pairs with the b frame nearest in time, when the gap is at most max_gap
//     (JEEP uses half of a's frame period). A b frame pairs at most once: when two a frames
//     want it, the nearer one keeps it (ties: the earlier a frame). Unpaired frames are skipped.
//   - Pairs come out in a's frame order. Timestamps must be finite and nondecreasing
//     (timestamps_usable); pair_frames returns no pairs otherwise.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "ulc/core/median.hpp"

namespace odometry {

struct FramePair {
  std::size_t a = 0;  ///< index into a's frames
  std::size_t b = 0;  ///< index into b's frames
};

inline bool timestamps_usable(const std::vector<double>& t) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i])) return false;
    if (i > 0 && t[i] < t[i - 1]) return false;
  }
  return true;
}

/// The median gap between consecutive timestamps; 0 with fewer than two frames.
inline double frame_period(const std::vector<double>& t) {
  return ulc::median_step(t);
}

inline std::vector<FramePair> pair_frames(const std::vector<double>& times_a,
                                          const std::vector<double>& times_b, double time_offset_s,
                                          double max_gap) {
  std::vector<FramePair> pairs;
  if (!timestamps_usable(times_a) || !timestamps_usable(times_b) || times_b.empty() ||
      !std::isfinite(time_offset_s) || !(max_gap >= 0.0))
    return pairs;
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> owner(times_b.size(), kNone);  // b frame -> a frame holding it
  std::vector<double> owner_gap(times_b.size(), 0.0);
  for (std::size_t i = 0; i < times_a.size(); ++i) {
    const double t = times_a[i] - time_offset_s;  // a's time in b's clock
    const auto it = std::lower_bound(times_b.begin(), times_b.end(), t);
    std::size_t j = static_cast<std::size_t>(it - times_b.begin());
    if (j == times_b.size() || (j > 0 && t - times_b[j - 1] <= times_b[j] - t)) --j;
    const double gap = std::abs(times_b[j] - t);
    if (!(gap <= max_gap)) continue;
    if (owner[j] != kNone && owner_gap[j] <= gap) continue;
    owner[j] = i;
    owner_gap[j] = gap;
  }
  for (std::size_t j = 0; j < times_b.size(); ++j)
    if (owner[j] != kNone) pairs.push_back({owner[j], j});
  std::sort(pairs.begin(), pairs.end(),
            [](const FramePair& x, const FramePair& y) { return x.a < y.a; });
  return pairs;
}

}  // namespace odometry
