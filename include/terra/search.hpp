// TERRA two-step rotation search (the paper's Sec. "Two-step Search Method").
//
// Finds R = R_base_target (p_base ~ R p_target) minimising eq:feature_dis between the base
// descriptor F1 and the rotated target descriptor rotate(F2, R):
//   Stage 0: the identity, then the 30 deg grid (rotation_grid.hpp) in order, until one rotation
//            gives a non-empty eq:mask: R0. If none does, R0 = identity and stage 1 still runs
//            (its finer grid can find an overlap the coarse one missed, e.g. a narrow FoV).
//   Stage 1: every rotation G_k R0 of the 10 deg grid; those with an empty mask, or a mask
//            below min_overlap_ratio of the largest one (SearchParams: not in the paper), are
//            dropped; the best top_k by (distance, grid index) are kept.
//   Stage 2: from each, a descent with the 26 moves exp(1 deg v) (rotation_grid.hpp): move to
//            the best neighbour (ties: move order) while it strictly lowers the distance.
//            The answer is the best optimum by (distance, seed rank).
// Every rotation is scored by rotated_distance (distance.hpp): no descriptor is rotated.
//
// Threads: stage 1 evaluates grid rotations in parallel and stage 2 runs the descents in
// parallel; each value lands in its own slot and every choice is an ordered comparison with
// index tie-breaks, so results are bit-identical for any thread count. Timings use
// std::chrono for the statistics only. Nothing here throws or prints.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numeric>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "terra/descriptor.hpp"
#include "terra/distance.hpp"
#include "terra/lattice.hpp"
#include "terra/rotation_grid.hpp"
#include "terra/search_params.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace terra {

namespace search_detail {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

inline std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// Whether a beats b: smaller distance, then smaller index.
inline bool better(const DistanceValue& a, std::size_t ia, const DistanceValue& b, std::size_t ib) {
  if (a.distance != b.distance) return a.distance < b.distance;
  return ia < ib;
}

/// Returns a reason when the parameters cannot be used, else an empty string.
inline std::string check_params(const SearchParams& p) {
  auto stride_ok = [](double deg) { return std::isfinite(deg) && deg > 0.0 && deg <= 180.0; };
  const DistanceParams& d = p.distance;
  if (!(std::isfinite(d.d1) && d.d1 >= 0.0)) return "d1 must be a finite number >= 0";
  if (!(std::isfinite(d.d2) && d.d2 >= 0.0)) return "d2 must be a finite number >= 0";
  if (!(std::isfinite(d.alpha) && d.alpha >= 0.0)) return "alpha must be a finite number >= 0";
  if (!stride_ok(p.overlap_stride_deg) || !stride_ok(p.coarse_stride_deg) ||
      !stride_ok(p.fine_stride_deg))
    return "search strides must be in (0, 180] degrees";
  if (p.top_k == 0) return "top_k must be at least 1";
  if (!(p.min_overlap_ratio >= 0.0 && p.min_overlap_ratio <= 1.0))
    return "min_overlap_ratio must be in [0, 1]";
  if (p.adaptive_d1.enabled &&
      !(p.adaptive_d1.percentile >= 0.0 && p.adaptive_d1.percentile <= 1.0 &&
        p.adaptive_d1.min_fraction >= 0.0 && p.adaptive_d1.min_fraction <= 1.0 &&
        std::isfinite(p.adaptive_d1.floor_m) && p.adaptive_d1.floor_m >= 0.0))
    return "adaptive d1: percentile and min_fraction must be in [0, 1], floor_m >= 0";
  return {};
}

/// The `q` quantile (nearest rank, q in [0, 1]) of a descriptor's filled ranges.
template <typename S>
double filled_percentile(const Descriptor<S>& f, double q) {
  std::vector<double> r;
  for (const S v : f.range)
    if (v > S(0)) r.push_back(static_cast<double>(v));
  if (r.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::round(q * static_cast<double>(r.size() - 1)));
  std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(k), r.end());
  return r[k];
}

/// d1 after the adaptive rule (AdaptiveD1), and whether it changed.
template <typename S1, typename S2>
std::pair<double, bool> choose_d1(const Descriptor<S1>& f1, const Descriptor<S2>& f2,
                                  const SearchParams& p) {
  double d1 = p.distance.d1;
  bool adapted = false;
  if (!p.adaptive_d1.enabled) return {d1, adapted};
  auto consider = [&](auto& f) {
    const double filled = static_cast<double>(f.filled_cells());
    if (filled > 0 &&
        static_cast<double>(f.cells_beyond(p.distance.d1)) < p.adaptive_d1.min_fraction * filled) {
      const double lowered =
          std::max(p.adaptive_d1.floor_m, filled_percentile(f, p.adaptive_d1.percentile));
      if (lowered < d1) {
        d1 = lowered;
        adapted = true;
      }
    }
  };
  consider(f1);
  consider(f2);
  return {d1, adapted};
}

}  // namespace search_detail

/// The search on two descriptors built on `lattice`. `lookup` answers the nearest-lattice-point
/// queries: the lattice itself (O(1)) or a KdTreeLookup on it (the paper's way, slower).
template <class Lookup, typename S1, typename S2>
SearchResult search_rotation(const Lattice& lattice, const Lookup& lookup,
                             const Descriptor<S1>& base, const Descriptor<S2>& target,
                             const SearchParams& params) {
  using namespace search_detail;
  SearchResult result;
  result.status = SearchStatus::invalid_input;
  if (std::string why = check_params(params); !why.empty()) {
    result.reason = why;
    return result;
  }
  if (lattice.empty() || lookup.size() != lattice.size()) {
    result.reason = "the lattice is empty or the lookup belongs to another lattice";
    return result;
  }
  if (base.size() != lattice.size() || target.size() != lattice.size()) {
    result.reason = "descriptor sizes differ from the lattice size";
    return result;
  }
  SearchStats& stats = result.stats;
  stats.base_filled = base.filled_cells();
  stats.target_filled = target.filled_cells();
  if (stats.base_filled == 0 || stats.target_filled == 0) {
    result.reason = std::string(stats.base_filled == 0 ? "base" : "target") +
                    " cloud has no point in the usable range (min_range .. max_range)";
    return result;
  }

  DistanceParams dp = params.distance;
  std::tie(dp.d1, stats.d1_adapted) = choose_d1(base, target, params);
  stats.d1_used = dp.d1;
  const BaseCells base_far = base_cells(lattice, base, dp.d1);
  const TargetCells target_far = target_cells(target, dp.d1);
  stats.base_beyond_d1 = base_far.size();
  stats.target_beyond_d1 = target.cells_beyond(dp.d1);
  result.status = SearchStatus::no_overlap;
  if (stats.base_beyond_d1 == 0 || stats.target_beyond_d1 == 0) {
    result.reason = std::string("no overlap is possible: the ") +
                    (stats.base_beyond_d1 == 0 ? "base" : "target") +
                    " cloud has no return beyond d1 = " + format_number(dp.d1) +
                    " m, and eq:mask only compares cells beyond d1 on both sides";
    return result;
  }
  auto evaluate = [&](const ulc::Mat3d& R) {
    return rotated_distance(base_far, target_far, lookup, R, dp);
  };
  auto report = [&](double fraction) {
    if (params.progress) params.progress(fraction);
  };
  report(0.0);

  // Stage 0: a first rotation with overlap.
  auto t0 = std::chrono::steady_clock::now();
  ulc::Mat3d R0 = ulc::Mat3d::Identity();
  {
    std::vector<ulc::Mat3d> coarse = so3_grid(params.overlap_stride_deg * ulc::kRadPerDeg);
    coarse.insert(coarse.begin(), ulc::Mat3d::Identity());
    for (const ulc::Mat3d& R : coarse) {
      ++stats.overlap.rotations;
      if (evaluate(R).overlap()) {
        R0 = R;
        stats.overlap_found_at_stage0 = true;
        break;
      }
    }
  }
  stats.overlap.seconds = seconds_since(t0);
  report(0.05);

  // Stage 1: the grid around R0, best top_k with overlap.
  t0 = std::chrono::steady_clock::now();
  const std::vector<ulc::Mat3d> grid = so3_grid(params.coarse_stride_deg * ulc::kRadPerDeg);
  std::vector<DistanceValue> values(grid.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k < r.end(); ++k)
                        values[k] = evaluate(grid[k] * R0);
                    });
  stats.coarse.rotations = grid.size();
  for (const DistanceValue& v : values)
    stats.max_mask_count = std::max(stats.max_mask_count, v.mask_count);
  stats.min_mask_count = std::max<std::size_t>(
      1, static_cast<std::size_t>(
             std::ceil(params.min_overlap_ratio * static_cast<double>(stats.max_mask_count))));
  const std::size_t min_count = stats.min_mask_count;
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < grid.size(); ++k)
    if (values[k].mask_count >= min_count) order.push_back(k);
  const std::size_t keep = std::min(params.top_k, order.size());
  std::partial_sort(
      order.begin(), order.begin() + static_cast<std::ptrdiff_t>(keep), order.end(),
      [&](std::size_t a, std::size_t b) { return better(values[a], a, values[b], b); });
  order.resize(keep);
  stats.coarse.seconds = seconds_since(t0);
  report(0.9);
  if (order.empty()) {
    stats.cell_evaluations = stats.rotations() * base_far.size();
    result.reason = "no overlap: none of the " + std::to_string(stats.rotations()) +
                    " rotations tried (" + format_number(params.overlap_stride_deg) + " and " +
                    format_number(params.coarse_stride_deg) +
                    " deg grids over SO(3)) gave a non-empty eq:mask (base cells beyond d1: " +
                    std::to_string(stats.base_beyond_d1) +
                    ", target: " + std::to_string(stats.target_beyond_d1) +
                    ", d1 = " + format_number(dp.d1) + " m, d2 = " + format_number(dp.d2) + " m)";
    return result;
  }
  for (const std::size_t k : order) {
    RotationCandidate c;
    c.rotation = grid[k] * R0;
    c.distance = values[k].distance;
    c.mask_count = values[k].mask_count;
    result.seeds.push_back(c);
  }

  // Stage 2: descend from each seed.
  t0 = std::chrono::steady_clock::now();
  const std::vector<ulc::Mat3d> moves = descent_moves(params.fine_stride_deg * ulc::kRadPerDeg);
  result.refined = result.seeds;
  std::vector<std::size_t> evaluations(result.seeds.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, result.seeds.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t s = r.begin(); s < r.end(); ++s) {
                        RotationCandidate& c = result.refined[s];
                        DistanceValue current;
                        current.distance = c.distance;
                        current.mask_count = c.mask_count;
                        for (std::size_t step = 0; step < params.max_descent_steps; ++step) {
                          DistanceValue best_value;
                          std::size_t best_move = moves.size();
                          for (std::size_t m = 0; m < moves.size(); ++m) {
                            DistanceValue v = evaluate(moves[m] * c.rotation);
                            ++evaluations[s];
                            if (v.mask_count < min_count) v = DistanceValue();  // too small
                            if (best_move == moves.size() || better(v, m, best_value, best_move)) {
                              best_value = v;
                              best_move = m;
                            }
                          }
                          if (!(best_value.distance < current.distance)) break;
                          c.rotation = moves[best_move] * c.rotation;
                          current = best_value;
                          ++c.descent_steps;
                        }
                        c.distance = current.distance;
                        c.mask_count = current.mask_count;
                      }
                    });
  stats.fine.rotations = std::accumulate(evaluations.begin(), evaluations.end(), std::size_t{0});
  stats.fine.seconds = seconds_since(t0);
  stats.cell_evaluations = static_cast<std::uint64_t>(stats.rotations()) * base_far.size();

  std::size_t best = 0;
  for (std::size_t s = 1; s < result.refined.size(); ++s)
    if (result.refined[s].distance < result.refined[best].distance) best = s;  // ties: rank
  result.status = SearchStatus::ok;
  result.reason.clear();
  result.rotation = result.refined[best].rotation;
  result.distance = result.refined[best].distance;
  result.mask_count = result.refined[best].mask_count;
  report(1.0);
  return result;
}

/// The search on the lattice's own O(1) lookup.
template <typename S1, typename S2>
SearchResult search_rotation(const Lattice& lattice, const Descriptor<S1>& base,
                             const Descriptor<S2>& target, const SearchParams& params = {}) {
  return search_rotation(lattice, lattice, base, target, params);
}

/// From clouds: builds both descriptors on `lattice` (params.descriptor) and searches.
/// R_base_target of the result maps target-frame points into the base frame.
template <class BaseCloud, class TargetCloud>
SearchResult estimate_rotation(const Lattice& lattice, const BaseCloud& base,
                               const TargetCloud& target, const SearchParams& params = {}) {
  SearchResult result;
  if (ulc::traits::size(base) == 0 || ulc::traits::size(target) == 0) {
    result.status = SearchStatus::invalid_input;
    result.reason = ulc::traits::size(base) == 0 ? "base cloud is empty" : "target cloud is empty";
    return result;
  }
  if (lattice.empty()) {
    result.status = SearchStatus::invalid_input;
    result.reason = "the lattice is empty (it needs N >= 2 points)";
    return result;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const auto f1 = make_descriptor(lattice, base, params.descriptor);
  const auto f2 = make_descriptor(lattice, target, params.descriptor);
  const double descriptor_seconds = search_detail::seconds_since(t0);
  result = search_rotation(lattice, f1, f2, params);
  result.stats.descriptor_seconds = descriptor_seconds;
  return result;
}

/// Same, building a lattice of params.lattice_size points first (reuse a Lattice across calls
/// when you can: building the N = 10000 table takes a noticeable fraction of a search).
template <class BaseCloud, class TargetCloud>
SearchResult estimate_rotation(const BaseCloud& base, const TargetCloud& target,
                               const SearchParams& params = {}) {
  if (params.lattice_size < 2) {
    SearchResult result;
    result.reason = "lattice_size must be at least 2";
    return result;
  }
  return estimate_rotation(Lattice(params.lattice_size), base, target, params);
}

}  // namespace terra
