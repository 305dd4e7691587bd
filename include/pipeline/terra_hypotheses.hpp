// TERRA's hypotheses: the distinct optima of one search, best first, for the pipeline to verify
// in turn (calibrate.hpp, CalibrateOptions::tuning.hypotheses.count).
//
// Why: on small-FoV pairs (a Tele-15 against a spinning LiDAR) the lowest eq:feature_dis is
// often not the true rotation but the street's forward/backward twin (~166 deg of yaw) or a
// neighbouring basin, while the true one is the search's second or third optimum (the
// colorful rig's Tele: rank 1, 2, 2 and 1 in four drives). The search already
// descends from top_k stage-1 seeds (search.hpp, stage 2); this keeps its optima, drops those
// within `separation_rad` of a better one (the same basin: JEEP converges from a few degrees),
// and orders them by (distance, seed rank), the search's own choice rule, so the first is
// always SearchResult::rotation.
//
// The fallback (fallback_hypotheses): when every one of those fails, the optima left over, of
// the kept search beyond the first few and then of the other search (automatic runs the frame
// search first and keeps the maps only when the frames overlap little, so both may exist; the
// caller chains the two), in each search's own order, without those within `separation_rad`
// of one already tried. Why:
// on the 90-deg-pitched VLP-16 (pitched-90, seed 1, 10 s) the map search's five optima are all
// 74-153 deg off, while the frame search's seventh is 3.2 deg off and leads JEEP and HOTS to
// 0.016 deg / 0.31 cm (docs/experiments/terra_fallback_hypotheses.md).
//
// Nothing here throws; deterministic (ordered comparisons only).
#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

#include "terra/search_params.hpp"
#include "ulc/core/pose_error.hpp"

namespace ulc {

/// Up to `max_count` optima of `search` at least `separation_rad` apart, best first; empty when
/// the search failed.
inline std::vector<terra::RotationCandidate> terra_hypotheses(const terra::SearchResult& search,
                                                              std::size_t max_count,
                                                              double separation_rad) {
  std::vector<terra::RotationCandidate> out;
  if (!search.ok()) return out;
  const auto& refined = search.refined;
  std::vector<std::size_t> order(refined.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return refined[a].distance < refined[b].distance;
  });
  for (const std::size_t k : order) {
    if (out.size() >= max_count) break;
    const bool distinct = std::none_of(out.begin(), out.end(), [&](const auto& kept) {
      return rotation_error_rad(kept.rotation, refined[k].rotation) < separation_rad;
    });
    if (distinct) out.push_back(refined[k]);
  }
  if (out.empty()) {  // a result built without its optima (never by search_rotation)
    terra::RotationCandidate best;
    best.rotation = search.rotation;
    best.distance = search.distance;
    best.mask_count = search.mask_count;
    out.push_back(best);
  }
  return out;
}

/// Up to `max_count` optima of `search`, in its own order, none within `separation_rad` of one
/// in `tried` or of one taken before it.
inline std::vector<terra::RotationCandidate> fallback_hypotheses(
    const terra::SearchResult& search, const std::vector<terra::RotationCandidate>& tried,
    std::size_t max_count, double separation_rad) {
  std::vector<terra::RotationCandidate> out;
  if (!search.ok()) return out;
  std::vector<terra::RotationCandidate> kept = tried;
  for (const auto& c : terra_hypotheses(search, search.refined.size(), separation_rad)) {
    if (out.size() >= max_count) break;
    const bool distinct = std::none_of(kept.begin(), kept.end(), [&](const auto& k) {
      return rotation_error_rad(k.rotation, c.rotation) < separation_rad;
    });
    if (!distinct) continue;
    out.push_back(c);
    kept.push_back(c);
  }
  return out;
}

}  // namespace ulc
