// Start search for the first calibration phase: the map-to-map registration (eq:calib_map) run
// from a few starts around the initial extrinsic, keeping the basin whose alignment explains
// the maps best.
//
// Why: from the paper's disturbance (5 deg, 2 m) the coarse stage's Gauss-Newton slides to the
// nearest minimum of its own cost. On a narrow-cone target (a Livox Tele) a turn and a shift
// across the view look alike, and that nearest minimum is often a wrong one, 5-20 deg and
// 10-15 m away, whose cost is higher than the truth's (measured on 64-tele: the truth's coarse
// cost was lower in every failure inspected). Starting also from turned and shifted copies of
// C and comparing the basins they reach finds the lower one.
//
// Conventions this header owns:
//   - Starts: C itself, C turned by +-rotation_step about each axis of the target's frame
//     (C exp(+-d e_i): a turn about the target LiDAR's centre), and C shifted by
//     +-translation_step along each axis of the base's frame: 13 in all, in that order.
//   - Each start runs the first calibration stage (coarse: wide gate, soft kernel). Results
//     within same_basin_rotation and same_basin_translation of a kept one are the same basin
//     and dropped; each kept basin runs the second stage and is scored there by its trimmed
//     cost: the mean over the second stage's source points of rho(r), a point without a plane
//     within the gate paying rho(gate), so that a pose cannot score well by leaving points
//     unmatched. Only basins within reach of C (reach_rotation, reach_translation: twice the
//     paper's disturbance) compete; the lowest score wins (ties: the earlier start, C's own
//     basin first), and C's own basin stands when none is within reach (a sparse scan can
//     pull a turned start 20-40 deg away to a spuriously low score). The remaining stages
//     run from the winner. With fewer than two stages, or the search off, it
//     is register_maps from C alone.
//   - Deterministic: starts run in order, each registration is thread-count independent.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "jeep/map_registration.hpp"
#include "jeep/options.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/types.hpp"

namespace jeep {

/// What the search did (zeros when it did not run).
struct StartSearchReport {
  std::size_t starts = 0;  ///< starts whose coarse stage ran
  std::size_t basins = 0;  ///< distinct basins scored
  std::size_t chosen = 0;  ///< index of the winning start (0: C itself)
  double chosen_score = 0.0;
  double own_score = 0.0;  ///< the score of C's own basin
};

/// C, C turned about each target axis, C shifted along each base axis (see top).
inline std::vector<Isometry3d> start_candidates(const Isometry3d& C,
                                                const StartSearchOptions& options) {
  std::vector<Isometry3d> out{C};
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {1.0, -1.0}) {
      ulc::Vec3d turn = ulc::Vec3d::Zero();
      turn[axis] = sign * options.rotation_step;
      Isometry3d turned = C;
      turned.linear() = C.linear() * ulc::so3_exp(turn);
      out.push_back(turned);
    }
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {1.0, -1.0}) {
      Isometry3d shifted = C;
      shifted.translation()[axis] += sign * options.translation_step;
      out.push_back(shifted);
    }
  return out;
}

/// Mean rho(r) over `points` at pose T, a point with no plane within the gate paying
/// rho(gate) (see top).
template <typename S>
double trimmed_cost(const std::vector<Vec3<S>>& points, const ulc::PlaneCloud<S>& target,
                    const Isometry3d& T, const ulc::RegistrationOptions& options) {
  if (points.empty()) return 0.0;
  std::vector<ulc::PointToPlaneTerm<S, ulc::PlaneCloud<S>>> terms(1);
  terms[0].points = points.data();
  terms[0].size = points.size();
  terms[0].target = &target;
  const ulc::PointToPlaneSums sums = ulc::sum_point_to_plane(terms, T, options);
  const double unmatched =
      static_cast<double>(points.size()) - static_cast<double>(sums.equations.count);
  return (sums.robust_cost + unmatched * options.kernel.rho(options.max_correspondence_distance)) /
         static_cast<double>(points.size());
}

namespace detail {

inline bool near_pose(const Isometry3d& X, const Isometry3d& Y, double translation,
                      double rotation) {
  const Isometry3d d = X.inverse() * Y;
  return d.translation().norm() <= translation && ulc::so3_log(d.linear()).norm() <= rotation;
}

inline bool seen_basin(const std::vector<Isometry3d>& basins, const Isometry3d& pose,
                       const StartSearchOptions& o) {
  for (const Isometry3d& b : basins)
    if (near_pose(b, pose, o.same_basin_translation, o.same_basin_rotation)) return true;
  return false;
}

inline bool within_reach(const Isometry3d& initial, const Isometry3d& pose,
                         const StartSearchOptions& o) {
  return near_pose(initial, pose, o.reach_translation, o.reach_rotation);
}

}  // namespace detail

/// register_maps from the best of the starts around `initial` (see top).
template <typename S>
RegistrationResult<double> register_maps_searching(const std::vector<Vec3<S>>& source,
                                                   const ulc::PlaneCloud<S>& target,
                                                   const Isometry3d& initial,
                                                   const MapRegistrationOptions& options,
                                                   const StartSearchOptions& search,
                                                   StartSearchReport* report = nullptr) {
  if (!search.enabled || options.stages.size() < 2)
    return register_maps(source, target, initial, options);
  MapRegistrationOptions coarse = options, second = options, rest = options;
  coarse.stages.assign(options.stages.begin(), options.stages.begin() + 1);
  second.stages.assign(options.stages.begin() + 1, options.stages.begin() + 2);
  rest.stages.erase(rest.stages.begin(), rest.stages.begin() + 2);
  const MapStage& scoring = options.stages[1];
  const auto scored_points = downsampled(source, scoring.source_voxel).points;

  StartSearchReport local;
  std::vector<Isometry3d> basins;
  RegistrationResult<double> best;
  bool best_within = false;  // best is C's own basin while no basin within reach was scored
  const std::vector<Isometry3d> starts = start_candidates(initial, search);
  for (std::size_t i = 0; i < starts.size(); ++i) {
    const auto reached = register_maps(source, target, starts[i], coarse);
    ++local.starts;
    const bool unusable = reached.status == ulc::RegistrationStatus::too_few_correspondences ||
                          reached.status == ulc::RegistrationStatus::invalid_input;
    if (unusable && i == 0) return reached;  // C itself cannot be registered: as register_maps
    if (unusable || detail::seen_basin(basins, reached.pose, search)) continue;
    basins.push_back(reached.pose);
    auto refined = register_maps(source, target, reached.pose, second);
    if (refined.status == ulc::RegistrationStatus::too_few_correspondences ||
        refined.status == ulc::RegistrationStatus::invalid_input) {
      if (i == 0) return refined;
      continue;
    }
    refined.iterations += reached.iterations;
    refined.solver_iterations += reached.solver_iterations;
    const double score = trimmed_cost(scored_points, target, refined.pose, scoring.registration);
    const bool within = detail::within_reach(initial, refined.pose, search);
    if (i == 0) local.own_score = score;
    const bool better = i == 0 || (within && (!best_within || score < local.chosen_score));
    if (!better) continue;
    best = refined;
    best_within = within;
    local.chosen = i;
    local.chosen_score = score;
  }
  local.basins = basins.size();
  if (report) *report = local;
  if (rest.stages.empty()) return best;
  auto result = register_maps(source, target, best.pose, rest);
  result.iterations += best.iterations;
  result.solver_iterations += best.solver_iterations;
  return result;
}

}  // namespace jeep
