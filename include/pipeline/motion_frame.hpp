// The motion frame: R_base_target from what every LiDAR of a moving vehicle shares whatever its
// field of view, the road under it and the way it moves. Not in the paper (issue 34: TERRA on
// narrow fields of view). Each LiDAR's local map over the window (map_terra.hpp) gives its
// travel from the window's first to its last frame and its largest planes, all in the LiDAR's
// frame at the anchor frame; both anchors were taken at about the same instant, so
//   R n_target = n_base   for the ground's normal (planes oriented towards the sensor), and
//   R d_target ~ d_base   for the travel (up to the lever arm times the window's turn),
// and two non-parallel directions fix R (the triad: the ground's normal and the travel's part
// along the ground).
//
// Conventions this header owns:
//   - Refused (ok = false, reason) when a LiDAR travelled less than min_travel_m (a parked or
//     slow rig has no direction of travel), when the two travels' lengths differ by more than
//     max_travel_mismatch (one odometry slipped: a narrow field of view looking along the
//     travel sees little that pins it), or when no pair of ground candidates makes both maps
//     share a surface.
//   - Ground candidates: each map's `planes` largest planes (terra/plane_fit.hpp, in turn) that
//     hold the travel within max_travel_tilt_deg (the vehicle drives on the road). A wall
//     along the street holds it too (a surface above both sensors, facing down, is no candidate
//     when a larger one faces up: ground_candidates); so every pair of candidates (base i, target
//     j) gives a rotation, and the pair whose rotation makes the two maps share the most surface
//     wins (planes paired when their normals agree within plane_match_deg and their distances to
//     the sensors within plane_match_m, each pair weighing the smaller of its planes' shares of
//     their maps; shared_surfaces); ties go to the larger planes (lower i, then j). A wall taken
//     for the ground, or the ground taken upside down, pairs the road with a small plane or none.
//   - Deterministic (seeded RANSAC, ordered choices); nothing here throws or prints.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/map_terra_options.hpp"
#include "terra/plane_fit.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// One LiDAR's view of its motion over the window: its travel and its largest planes, in its
/// frame at the anchor frame.
struct MotionView {
  Vec3d travel = Vec3d::Zero();
  std::vector<terra::PlaneFit> planes;  ///< largest first
};

namespace motion_detail {

inline double angle_deg(const Vec3d& a, const Vec3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kRadPerDeg;
}

/// Columns: the travel's part along the ground, the third axis, the ground's normal.
inline Mat3d triad(const Vec3d& normal, const Vec3d& travel) {
  const Vec3d up = normal.normalized();
  const Vec3d along = (travel - travel.dot(up) * up).normalized();
  Mat3d m;
  m.col(0) = along;
  m.col(1) = up.cross(along);
  m.col(2) = up;
  return m;
}

/// The planes that hold the travel (ground candidates), by index, largest first; a plane facing
/// the opposite way to a larger candidate (within 30 deg) is not one: a surface above both
/// sensors (an overhang, a canopy) is smaller than the road under them, and taken for the
/// ground it would turn the rig upside down.
inline std::vector<std::size_t> ground_candidates(const MotionView& v,
                                                  const MotionFrameOptions& o) {
  std::vector<std::size_t> out;
  const double most = std::sin(o.max_travel_tilt_deg * kRadPerDeg);
  const double opposite = -std::cos(30.0 * kRadPerDeg);
  for (std::size_t k = 0; k < v.planes.size(); ++k) {
    const Vec3d& n = v.planes[k].normal;
    if (std::fabs(n.dot(v.travel.normalized())) > most) continue;
    const bool faces_a_larger = std::any_of(out.begin(), out.end(), [&](std::size_t c) {
      return v.planes[c].normal.dot(n) < opposite;
    });
    if (!faces_a_larger) out.push_back(k);
  }
  return out;
}

/// The surfaces both maps share under R: each base plane paired with the first target plane
/// not yet taken whose normal (turned by R) and distance agree. Returns their count and their
/// weight, the sum over pairs of the smaller of the two planes' shares of its map's points:
/// the road matched to the road weighs most, so a pairing that matches the road to a small
/// plane (the road taken upside down against an overhang above both sensors) weighs little.
inline std::pair<std::size_t, double> shared_surfaces(const MotionView& a, const MotionView& b,
                                                      const Mat3d& R, const MotionFrameOptions& o) {
  auto share = [](const MotionView& v, const terra::PlaneFit& p) {
    const std::size_t total = v.planes.front().used;
    return total ? static_cast<double>(p.inliers) / static_cast<double>(total) : 0.0;
  };
  std::vector<bool> taken(b.planes.size(), false);
  std::size_t count = 0;
  double weight = 0.0;
  for (const terra::PlaneFit& pa : a.planes) {
    for (std::size_t k = 0; k < b.planes.size(); ++k) {
      const terra::PlaneFit& pb = b.planes[k];
      if (taken[k] || angle_deg(R * pb.normal, pa.normal) > o.plane_match_deg ||
          std::fabs(pa.offset - pb.offset) > o.plane_match_m)
        continue;
      taken[k] = true;
      ++count;
      weight += std::min(share(a, pa), share(b, pb));
      break;
    }
  }
  return {count, weight};
}

/// A reason when the travels cannot be used, else empty.
inline std::string travel_problem(double la, double lb, const MotionFrameOptions& o) {
  auto metres = [](double v) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.2f m", v);
    return std::string(text);
  };
  if (!(std::min(la, lb) >= o.min_travel_m))
    return "the rig travelled " + metres(std::min(la, lb)) + " over the window (at least " +
           metres(o.min_travel_m) + " needed for a direction of travel)";
  if (std::fabs(la - lb) > o.max_travel_mismatch * std::max(la, lb))
    return "the two LiDARs' odometries disagree on the distance travelled (" + metres(la) +
           " against " + metres(lb) + ")";
  return {};
}

}  // namespace motion_detail

/// The largest planes and the travel of one local map, for motion_rotation.
template <class Points>
MotionView motion_view(const Points& map_points, const Vec3d& travel, const MotionFrameOptions& o) {
  MotionView v;
  v.travel = travel;
  v.planes = terra::largest_planes(map_points, o.planes, o.min_plane_points);
  return v;
}

/// R_base_target from the two views (see the conventions above).
inline MotionReport motion_rotation(const MotionView& a, const MotionView& b,
                                    const MotionFrameOptions& o) {
  using namespace motion_detail;
  MotionReport r;
  r.travel_base_m = a.travel.norm();
  r.travel_target_m = b.travel.norm();
  r.planes_base = a.planes.size();
  r.planes_target = b.planes.size();
  if (std::string why = travel_problem(r.travel_base_m, r.travel_target_m, o); !why.empty()) {
    r.reason = std::move(why);
    return r;
  }
  double best = 0.0;
  for (const std::size_t i : ground_candidates(a, o)) {
    for (const std::size_t j : ground_candidates(b, o)) {
      const Mat3d R =
          triad(a.planes[i].normal, a.travel) * triad(b.planes[j].normal, b.travel).transpose();
      const auto [matched, weight] = shared_surfaces(a, b, R, o);
      if (!(weight > best)) continue;
      best = weight;
      r.planes_matched = matched;
      r.rotation = R;
    }
  }
  r.ok = r.planes_matched > 0;
  if (!r.ok)
    r.reason = "no ground both maps share: of " + std::to_string(r.planes_base) + " and " +
               std::to_string(r.planes_target) +
               " planes, none holding the travel lines up with the other map's";
  return r;
}

}  // namespace ulc
