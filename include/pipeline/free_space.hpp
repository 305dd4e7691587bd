// The free-space check on a static snapshot's answer: does the extrinsic put the target's points
// where the base's own rays passed through empty space? Not in the paper.
//
// Why: a parked rig has one frame per LiDAR, so HOTS (whose cross links judge a moving rig's
// answer) cannot run, and JEEP's acceptance judges only how well the two clouds' surfaces agree
// where they meet. A street's or a sensor's twin can agree there: on pitched-90 parked (seed 10)
// JEEP accepted a rotation 180 deg and 7 m from the truth with an off-ground overlap above the
// rule's. What the overlap does not see is the rest of the target's cloud: placed by the twin,
// 28 % of it lies in space the base looked through (3-11 % at the truth). A ray is evidence both
// ways: its hit says "something is here", the voxels it crossed say "nothing is here".
// Both LiDARs' rays are read: the base's (the target's points where the base saw through) and
// the target's own (its rays, placed by the answer, through surfaces the base saw and the target
// did not). The second caught the twin the first let through: flicar-lift parked, seed 16's
// Avia, 161.8 deg and 13.9 m off, 17 % of its points in the base's empty space (a right Avia
// reaches 16 %), but 64 % of its rays through the base's walls (at the truth 0 %).
//
// Conventions:
//   - The seen space is a cube of voxels (FreeSpaceOptions::voxel) about the base's origin,
//     +-range on each axis: a voxel holding a base point is occupied; one crossed by a base ray
//     from one voxel out to 1.5 voxels short of its hit is free (unless occupied). Rays longer
//     than the range mark free space to the cube's edge; returns that never came back (sky)
//     mark nothing.
//   - A judged target point (every stride-th, moved by T_base_target) is one in a voxel that is
//     occupied, next to an occupied one (26 neighbours: the two LiDARs sample a surface at
//     different places; a grazing ray crosses the voxels of the ground it is about to hit), or
//     free; it contradicts when free and not next to an occupied one.
//   - A judged target ray (from the target's origin to a judged point, at least 2 voxels long)
//     is one whose samples (every half voxel, from one voxel out to 2.5 voxels short of its hit:
//     the hit's own surface is the point test's) meet the base's seen space; it goes through
//     when a sample lies in a voxel the base saw occupied with no target point in that voxel or
//     its 26 neighbours (a ray grazing the ground crosses voxels of the ground both saw).
//   - Deterministic (serial, in point order); nothing here throws; the allocation is bounded by
//     the options (free_space_problem refuses a cube over kMaxCells).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "pipeline/free_space_options.hpp"
#include "terra/occupancy_grid.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

namespace free_space_detail {

/// 256^3 voxels: the defaults use 240^3.
constexpr double kMaxCells = 16777216.0;

/// A cube of voxels about the base's origin (terra::OccupancyGrid, one state byte per voxel):
/// unknown, free or occupied.
class SeenSpace {
 public:
  static constexpr std::uint8_t kUnknown = 0, kFree = 1, kOccupied = 2;

  SeenSpace(double voxel, double range) : grid_(voxel, range, -range, range), range_(range) {}

  /// Every finite point of `cloud` occupies its voxel and frees those its ray crossed (an
  /// occupied voxel stays occupied whichever ray crosses it, before or after).
  template <class Cloud>
  void add_frame(const Cloud& cloud) {
    add_points(cloud, true);
  }

  /// Every finite point of `cloud` occupies its voxel; no ray is traced.
  template <class Cloud>
  void add_hits(const Cloud& cloud) {
    add_points(cloud, false);
  }

  std::uint8_t at(const Vec3d& p) const { return grid_.value(p); }

  bool near_occupied(const Vec3d& p) const {
    const double v = grid_.voxel();
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          if (at(p + v * Vec3d(dx, dy, dz)) == kOccupied) return true;
    return false;
  }

 private:
  template <class Cloud>
  void add_points(const Cloud& cloud, bool trace_rays) {
    for (std::size_t i = 0; i < traits::size(cloud); ++i) {
      const Vec3d p = traits::point(cloud, i).template cast<double>();
      if (!p.allFinite()) continue;
      if (std::uint8_t* c = grid_.cell(p)) *c = kOccupied;
      if (trace_rays) free_ray(p);
    }
  }

  void free_ray(const Vec3d& hit) {
    const double r = hit.norm(), v = grid_.voxel();
    if (!(r > 0.0)) return;
    const double end = std::min(r - 1.5 * v, std::sqrt(3.0) * range_);
    const Vec3d u = hit / r;
    for (double t = v; t < end; t += 0.5 * v) {
      std::uint8_t* c = grid_.cell(t * u);
      if (!c) return;  // left the cube: nothing farther is in it
      if (*c == kUnknown) *c = kFree;
    }
  }

  terra::OccupancyGrid grid_;
  double range_;
};

/// What one target ray showed: whether it met the base's seen space, and whether it went through
/// a surface only the base saw (see the conventions).
struct RayState {
  bool judged = false, through = false;
};

/// The target's rays placed by T_base_target in the base's seen space, against the target's own
/// hits (`own`, in the target's frame). The samples are taken only where a ray can be inside the
/// base's cube (within sqrt(3) range of the base's origin), so a far hit or a far answer costs
/// at most 7 range / voxel samples.
class TargetRays {
 public:
  TargetRays(const SeenSpace& base, const SeenSpace& own, const Isometry3d& T_base_target,
             double voxel, double range)
      : base_(base), own_(own), T_(T_base_target), voxel_(voxel) {
    const double origin = T_base_target.translation().norm(), reach = std::sqrt(3.0) * range;
    nearest_ = std::max(voxel, origin - reach);
    farthest_ = origin + reach;
  }

  /// The ray from the target's origin to `hit` (in the target's frame).
  RayState walk(const Vec3d& hit) const {
    RayState state;
    const double r = hit.norm();
    if (!(r >= 2.0 * voxel_)) return state;
    const Vec3d u = hit / r;
    const double end = std::min(r - 2.5 * voxel_, farthest_);
    for (double t = nearest_; t < end; t += 0.5 * voxel_) {
      const std::uint8_t seen = base_.at(T_ * (t * u));
      if (seen == SeenSpace::kUnknown) continue;
      state.judged = true;
      if (seen == SeenSpace::kOccupied && !own_.near_occupied(t * u)) {
        state.through = true;
        return state;
      }
    }
    return state;
  }

 private:
  const SeenSpace& base_;
  const SeenSpace& own_;
  Isometry3d T_;
  double voxel_, nearest_ = 0.0, farthest_ = 0.0;
};

}  // namespace free_space_detail

/// Why the options cannot be used; empty when they can.
inline std::string free_space_problem(const FreeSpaceOptions& o) {
  if (!(o.voxel > 0.0) || !(o.range > 0.0) || !std::isfinite(o.range))
    return "free space: voxel and range must be positive";
  if (std::pow(std::ceil(2.0 * o.range / o.voxel), 3.0) > free_space_detail::kMaxCells)
    return "free space: range / voxel too large (at most 256 voxels along each axis)";
  if (o.stride == 0) return "free space: stride must be at least 1";
  if (!(o.min_off_ground_overlap >= 0.0 && o.min_off_ground_overlap <= 1.0))
    return "free space: min_off_ground_overlap must lie in [0, 1]";
  return "";
}

/// The check on `target` placed by T_base_target in what `base` saw (see the conventions);
/// nothing judged when the options are unusable.
template <class BaseCloud, class TargetCloud>
FreeSpaceVerdict free_space_verdict(const BaseCloud& base, const TargetCloud& target,
                                    const Isometry3d& T_base_target, const FreeSpaceOptions& o) {
  using free_space_detail::SeenSpace;
  FreeSpaceVerdict v;
  if (!free_space_problem(o).empty()) return v;
  SeenSpace seen(o.voxel, o.range), own(o.voxel, o.range);
  seen.add_frame(base);
  own.add_hits(target);
  const free_space_detail::TargetRays rays(seen, own, T_base_target, o.voxel, o.range);
  for (std::size_t i = 0; i < traits::size(target); i += o.stride) {
    const Vec3d hit = traits::point(target, i).template cast<double>();
    const Vec3d p = T_base_target * hit;
    if (!p.allFinite()) continue;
    const free_space_detail::RayState ray = rays.walk(hit);
    v.rays_judged += ray.judged ? 1 : 0;
    v.rays_through += ray.through ? 1 : 0;
    const std::uint8_t state = seen.at(p);
    const bool near = state == SeenSpace::kOccupied || seen.near_occupied(p);
    if (state == SeenSpace::kUnknown && !near) continue;
    ++v.judged;
    if (state == SeenSpace::kFree && !near) ++v.contradicting;
  }
  return v;
}

/// An answer JEEP accepted only at the check's lower off-ground overlap (below JEEP's own
/// `jeep_bound`; FreeSpaceOptions::min_off_ground_overlap) stands only when the checks behind
/// that bound judged it: the free-space check, on at least min_points of its points and of its
/// rays (`v`: empty when it could not run, the target having moved between the two frames), and
/// the two-way verdict, which needs JEEP's backward registration to have succeeded
/// (`two_way_applied`; a twin whose backward registration failed passed the free-space check at
/// 20 %: horizon-tele parked, seed 12, docs/experiments/snapshot_acceptance.md). The refusal
/// in words, or empty.
inline std::string unvouched_overlap_refusal(double off_ground_overlap, double jeep_bound,
                                             const std::optional<FreeSpaceVerdict>& v,
                                             bool two_way_applied, const FreeSpaceOptions& o) {
  if (off_ground_overlap >= jeep_bound) return "";
  const bool judged = v && v->judged >= o.min_points && v->rays_judged >= o.min_points;
  if (judged && two_way_applied) return "";
  const char* missing =
      "JEEP's backward registration failed, so its two directions could not be compared";
  if (!v)
    missing = "the free-space check could not run (the target moved between the two frames)";
  else if (!judged)
    missing = "the free-space check judged too few of the target's points or rays";
  char text[400];
  std::snprintf(text, sizeof text,
                "JEEP: the maps agree off the ground at %.2f, below %.2f, which a snapshot's "
                "answer may only with the free-space check and the two-way verdict behind it: %s",
                off_ground_overlap, jeep_bound, missing);
  return text;
}

}  // namespace ulc
