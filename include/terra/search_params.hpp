// Parameters and results of the TERRA two-step rotation search (search.hpp).
//
// Defaults are the paper's (table:parameters and Sec. "Two-step Search Method"): N = 10000,
// d1 = 20 m, d2 = 5 m, alpha = 2, first-stage stride 10 deg, second-stage stride 1 deg, the
// best 10 first-stage rotations refined, and a 30 deg stride to find a first overlap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "terra/descriptor.hpp"
#include "terra/distance.hpp"
#include "ulc/core/types.hpp"

namespace terra {

/// Lowers d1 for short-range LiDARs and enclosed places, where returns rarely reach 20 m
/// (eq:mask would keep almost nothing). When fewer than `min_fraction` of a descriptor's filled
/// cells lie beyond d1, d1 becomes the `percentile` of that descriptor's filled ranges (the
/// smaller one if both qualify), but never less than `floor_m`: below a few metres the
/// parallax of the offset between the two LiDARs (up to a vehicle's size, the paper's d2 = 5 m)
/// swamps the ranges, and "no overlap" is the honest answer. Not in the paper. On by default,
/// as measured with bench_terra --accuracy (18 simulated rig pairs, 50 randomly turned frame
/// pairs each): it fired in the tunnel (19 of 50 frames, d1 ~7 m; success 68% -> 86%, median
/// error 5.6 -> 3.0 deg) and in 2 frames of flicar-lift (success 42% -> 38%); it never fired
/// anywhere else, so nothing else changed.
struct AdaptiveD1 {
  bool enabled = true;
  double min_fraction = 0.05;  ///< of filled cells beyond d1
  double percentile = 0.5;     ///< in [0, 1] of the filled ranges
  double floor_m = 5.0;        ///< the lowest d1 the rule may choose
};

struct SearchParams {
  std::size_t lattice_size = 10000;     ///< N; used only by the overloads that build the lattice
  DistanceParams distance;              ///< d1, d2, alpha (eq:mask, eq:feature_dis)
  double overlap_stride_deg = 30.0;     ///< stage 0: grid used to find a first overlap
  double coarse_stride_deg = 10.0;      ///< stage 1: grid over all of SO(3)
  double fine_stride_deg = 1.0;         ///< stage 2: descent step
  std::size_t top_k = 10;               ///< stage-1 rotations refined by stage 2
  std::size_t max_descent_steps = 100;  ///< per seed; 1 deg steps from a 10 deg grid need ~10
  /// Not in the paper: after stage 1, rotations whose eq:mask holds fewer than this fraction of
  /// the largest mask count seen in stage 1 count as no overlap (in stage 1's ranking and in
  /// stage 2's moves). eq:feature_dis divides by count^alpha, yet a rotation that lines up one
  /// or a few dozen cells by chance (one cell at a millimetre, or a ring of far ground cells
  /// under a wrong yaw) can still score below the true rotation's hundreds of cells at
  /// sensor-noise differences. Measured with bench_terra --accuracy (18 simulated rig pairs x
  /// 50 randomly turned frame pairs): 251 of 900 successes with 0 (the paper's rule), 553 with
  /// 0.2; e.g. 64-32 44% -> 96%, 64-horizon 0% -> 86%. 0 restores the paper's rule.
  double min_overlap_ratio = 0.2;
  AdaptiveD1 adaptive_d1;
  DescriptorOptions descriptor;  ///< min_range etc., for the overloads that take clouds
  /// Optional: called on the calling thread between stages with the fraction done (0..1).
  std::function<void(double)> progress;
};

enum class SearchStatus {
  ok,             ///< rotation found
  no_overlap,     ///< no candidate rotation had a non-empty eq:mask
  invalid_input,  ///< empty clouds, mismatched descriptors or unusable parameters
};

inline const char* to_string(SearchStatus s) {
  switch (s) {
    case SearchStatus::ok:
      return "ok";
    case SearchStatus::no_overlap:
      return "no_overlap";
    default:
      return "invalid_input";
  }
}

struct RotationCandidate {
  ulc::Mat3d rotation = ulc::Mat3d::Identity();  ///< R_base_target
  double distance = std::numeric_limits<double>::infinity();
  std::size_t mask_count = 0;
  std::size_t descent_steps = 0;  ///< stage 2: moves made from the seed
};

struct StageStats {
  std::size_t rotations = 0;  ///< rotations evaluated (each one fused distance)
  double seconds = 0.0;       ///< wall time (statistics only)
};

struct SearchStats {
  StageStats overlap;                  ///< stage 0
  StageStats coarse;                   ///< stage 1
  StageStats fine;                     ///< stage 2
  double descriptor_seconds = 0.0;     ///< when the search built the descriptors
  std::uint64_t cell_evaluations = 0;  ///< lattice lookups in the fused loop, all stages
  std::size_t base_filled = 0, target_filled = 0;        ///< non-empty cells
  std::size_t base_beyond_d1 = 0, target_beyond_d1 = 0;  ///< cells > d1 used
  double d1_used = 0.0;                                  ///< after the adaptive rule
  bool d1_adapted = false;
  bool overlap_found_at_stage0 = false;  ///< stage 0 found an overlapping start rotation
  std::size_t max_mask_count = 0;        ///< largest eq:mask count of stage 1
  std::size_t min_mask_count = 0;        ///< from min_overlap_ratio: smaller masks are ignored
  std::size_t rotations() const { return overlap.rotations + coarse.rotations + fine.rotations; }
  double seconds() const { return overlap.seconds + coarse.seconds + fine.seconds; }
};

struct SearchResult {
  SearchStatus status = SearchStatus::invalid_input;
  std::string reason;                            ///< empty when ok
  ulc::Mat3d rotation = ulc::Mat3d::Identity();  ///< R_base_target: p_base ~ R p_target
  double distance = std::numeric_limits<double>::infinity();  ///< eq:feature_dis at rotation
  std::size_t mask_count = 0;
  std::vector<RotationCandidate> seeds;    ///< stage-1 best, best first
  std::vector<RotationCandidate> refined;  ///< stage-2 optimum of each seed, same order
  SearchStats stats;
  bool ok() const { return status == SearchStatus::ok; }
};

}  // namespace terra
