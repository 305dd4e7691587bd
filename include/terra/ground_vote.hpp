// The ground vote: R_base_target, with no prior, from one target frame and a base cloud (a
// local map) when both see the road. Not in the paper (issue 34: TERRA on narrow fields of
// view). With each cloud levelled on its ground, what is left is one angle (the yaw about the
// ground's normal) and the lever arm along the ground; every target point above the ground
// that lands on a surface the base saw is one vote, so a narrow field of view that fills a
// dozen of TERRA's lattice cells still brings hundreds of votes. Measured in
// docs/experiments/terra_ground_vote.md.
//
// Conventions this header owns:
//   - Levelling: a plane n.p + d = 0 (normal towards the sensor, plane_fit.hpp) taken as the
//     ground maps p to (L p).x, (L p).y and the height n.p + d, L = levelling_rotation(n).
//   - The base's ground is its largest plane; the target's is each of its `target_planes`
//     largest planes in turn (a narrow LiDAR's largest plane may be a wall) whose distance to
//     the target is within max_height_difference of the base's height above its ground.
//   - Votes: the target's points with heights in [min_height, max_height) within max_range
//     (horizontal), one per voxel, at most max_points (every k-th of the voxels in key order).
//     The score of (yaw, tx, ty) is the share of them that land in a voxel the base occupies
//     after Rz(yaw) and the shift (tx, ty, 0); |tx|, |ty| <= max_translation.
//   - The base's voxels: each base point's, and those above and below it within half of
//     base_ring_gap_deg seen from the base (the origin of its cloud): a spinning base's rings
//     then meet a dense target's points that fell between them.
//   - Search: yaw over the circle in coarse_step_deg on a grid of twice the voxel, translation
//     in steps of that voxel; the peaks_per_plane best local maxima (peak_separation_deg
//     apart) refined in fine_step_deg within one coarse step on the fine grid, translation in
//     voxel steps over the whole range.
//   - Margin: the best refined score over the best of the refined peaks whose rotation lies
//     more than margin_separation_deg from the winner's (infinite when there is none).
//   - Grounds with fewer than min_points voxels above them do not vote (none left: refused).
//   - ok (a confident answer) when at least min_score of the votes landed and the margin is at
//     least min_margin; otherwise the best answer is still filled in, with the reason.
//   - Result: R = L_b^T Rz(yaw) L_t and t = L_b^T (tx, ty, d_t - d_b); every refined peak's
//     pose is kept (GroundVoteResult::peaks) for the window's pooled vote.
//   - A pose from elsewhere (pose_share): the target ground it turns within pose_tilt_deg of
//     the base's, its yaw and shift read back through the levellings, then the best share over
//     yaws within one coarse step and shifts within pose_shift_voxels on the fine grid.
//   - Free space (add_free_space, optional): the fine voxels a raw base frame's rays crossed,
//     from its origin to one voxel short of each hit. pose_share counts a point landing there,
//     and on no surface, as a vote against (a pose's share is never below 0); the single
//     frame's own search (ground_vote) does not use it.
//   - Deterministic: per-yaw and per-peak slots filled in parallel, reduced in order; nothing
//     here throws or prints.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "terra/ground_vote_options.hpp"
#include "terra/occupancy_grid.hpp"
#include "terra/plane_fit.hpp"
#include "terra/scan_context.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/types.hpp"
#include "ulc/core/voxel.hpp"

namespace terra {

namespace ground_vote_detail {

/// Point `p` levelled on `plane` (see the conventions): turned by the plane's levelling
/// rotation `L`, its height the signed distance above the plane.
inline ulc::Vec3d levelled_point(const ulc::Mat3d& L, const PlaneFit& plane, const ulc::Vec3d& p) {
  ulc::Vec3d q = L * p;
  q.z() = plane.normal.dot(p) + plane.offset;
  return q;
}

/// A cloud's points levelled on `plane` (see the conventions), above the ground and in range.
template <class Cloud>
std::vector<ulc::Vec3d> levelled(const Cloud& cloud, const PlaneFit& plane,
                                 const GroundVoteOptions& o) {
  const ulc::Mat3d L = levelling_rotation(plane.normal);
  std::vector<ulc::Vec3d> out;
  for (std::size_t i = 0; i < ulc::traits::size(cloud); ++i) {
    const ulc::Vec3d p = ulc::traits::point(cloud, i).template cast<double>();
    if (!p.allFinite() || p.norm() < o.plane.min_range) continue;
    const ulc::Vec3d q = levelled_point(L, plane, p);
    if (q.z() >= o.min_height && q.z() < o.max_height && q.head<2>().norm() <= o.max_range)
      out.push_back(q);
  }
  return out;
}

/// One point per voxel (the first in key order), then every k-th so at most max_points stay.
inline std::vector<ulc::Vec3d> one_per_voxel(const std::vector<ulc::Vec3d>& pts, double voxel,
                                             std::size_t max_points) {
  std::vector<std::pair<ulc::VoxelKey, std::size_t>> keys;
  keys.reserve(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i)
    // Always a key: levelled points lie within max_range and max_height (options_problem).
    if (const auto k = ulc::make_voxel_key(pts[i], voxel)) keys.emplace_back(*k, i);
  std::sort(keys.begin(), keys.end());
  std::vector<ulc::Vec3d> out;
  for (std::size_t k = 0; k < keys.size(); ++k)
    if (k == 0 || keys[k].first != keys[k - 1].first) out.push_back(pts[keys[k].second]);
  if (max_points > 0 && out.size() > max_points) {
    const std::size_t step = (out.size() + max_points - 1) / max_points;
    std::size_t n = 0;
    for (std::size_t k = 0; k < out.size(); k += step) out[n++] = out[k];
    out.resize(n);
  }
  return out;
}

inline OccupancyGrid base_grid(const std::vector<ulc::Vec3d>& base, double voxel,
                               const GroundVoteOptions& o) {
  OccupancyGrid g(voxel, o.max_range + o.max_translation + voxel, o.min_height, o.max_height);
  // Each base point also fills its column up and down half the ring gap, seen from the anchor.
  const double slope = std::tan(0.5 * o.base_ring_gap_deg * ulc::kRadPerDeg);
  for (const ulc::Vec3d& p : base) {
    const int n = static_cast<int>(std::floor(p.head<2>().norm() * slope / voxel + 0.5));
    for (int k = -n; k <= n; ++k) g.mark(p + ulc::Vec3d(0.0, 0.0, k * voxel));
  }
  return g;
}

/// A yaw, the shift along the ground, and the votes they gather.
struct Peak {
  double yaw_deg = 0.0;
  double tx = 0.0, ty = 0.0;
  std::size_t votes = 0;
  std::size_t plane = 0;
};

/// The best shift of the target turned by `yaw_deg` among (cx + a step, cy + b step),
/// |a|, |b| <= n, step the grid's voxel (ties: the first in x then y). With `free`, a point
/// landing in a free voxel the grid does not occupy takes a vote away (none below zero).
inline Peak best_shift_near(const OccupancyGrid& grid, const std::vector<ulc::Vec3d>& target,
                            double yaw_deg, double cx, double cy, int n,
                            const OccupancyGrid* free = nullptr) {
  const double step = grid.voxel();
  const int side = 2 * n + 1;
  std::vector<long> votes(static_cast<std::size_t>(side * side), 0);
  const double c = std::cos(yaw_deg * ulc::kRadPerDeg), s = std::sin(yaw_deg * ulc::kRadPerDeg);
  for (const ulc::Vec3d& p : target) {
    const ulc::Vec3d q(c * p.x() - s * p.y() + cx, s * p.x() + c * p.y() + cy, p.z());
    for (int a = -n; a <= n; ++a)
      for (int b = -n; b <= n; ++b) {
        const ulc::Vec3d x = q + ulc::Vec3d(a * step, b * step, 0.0);
        votes[static_cast<std::size_t>((a + n) * side + b + n)] +=
            grid.occupied(x) ? 1 : (free && free->occupied(x) ? -1 : 0);
      }
  }
  Peak best;
  best.yaw_deg = yaw_deg;
  for (int a = -n; a <= n; ++a)
    for (int b = -n; b <= n; ++b) {
      const long v = votes[static_cast<std::size_t>((a + n) * side + b + n)];
      if (v > 0 && std::size_t(v) > best.votes)
        best.votes = std::size_t(v), best.tx = cx + a * step, best.ty = cy + b * step;
    }
  return best;
}

/// The best shift within max_translation, in steps of the grid's voxel.
inline Peak best_shift(const OccupancyGrid& grid, const std::vector<ulc::Vec3d>& target,
                       double yaw_deg, const GroundVoteOptions& o) {
  const int n = static_cast<int>(std::floor(o.max_translation / grid.voxel()));
  return best_shift_near(grid, target, yaw_deg, 0.0, 0.0, n);
}

/// Each yaw's best shift, for yaws first, first + step, ... (count of them), in parallel.
inline std::vector<Peak> sweep(const OccupancyGrid& grid, const std::vector<ulc::Vec3d>& target,
                               double first_deg, double step_deg, std::size_t count,
                               const GroundVoteOptions& o) {
  std::vector<Peak> out(count);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k < r.end(); ++k)
                        out[k] = best_shift(grid, target, first_deg + step_deg * double(k), o);
                    });
  return out;
}

inline double yaw_gap_deg(double a, double b) {
  return std::fabs(std::remainder(a - b, 360.0));
}

/// The `count` best local maxima of a circular sweep, at least `separation` deg apart.
inline std::vector<Peak> best_peaks(const std::vector<Peak>& sweep, std::size_t count,
                                    double separation) {
  std::vector<Peak> maxima;
  const std::size_t n = sweep.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Peak& p = sweep[k];
    if (p.votes > 0 && p.votes >= sweep[(k + n - 1) % n].votes &&
        p.votes >= sweep[(k + 1) % n].votes)
      maxima.push_back(p);
  }
  std::stable_sort(maxima.begin(), maxima.end(),
                   [](const Peak& a, const Peak& b) { return a.votes > b.votes; });
  std::vector<Peak> out;
  for (const Peak& p : maxima) {
    if (out.size() == count) break;
    if (std::none_of(out.begin(), out.end(),
                     [&](const Peak& q) { return yaw_gap_deg(p.yaw_deg, q.yaw_deg) < separation; }))
      out.push_back(p);
  }
  return out;
}

/// One target ground candidate, levelled and thinned.
struct TargetGround {
  PlaneFit plane;
  std::vector<ulc::Vec3d> points;
};

/// The refined peak nearest `coarse` (within one coarse step either side).
inline Peak refine(const OccupancyGrid& fine, const TargetGround& t, const Peak& coarse,
                   const GroundVoteOptions& o) {
  const auto half = static_cast<std::size_t>(std::floor(o.coarse_step_deg / o.fine_step_deg));
  const std::vector<Peak> local =
      sweep(fine, t.points, coarse.yaw_deg - o.fine_step_deg * double(half), o.fine_step_deg,
            2 * half + 1, o);
  Peak best = local.front();
  for (const Peak& p : local)
    if (p.votes > best.votes) best = p;
  best.plane = coarse.plane;
  return best;
}

inline ulc::Mat3d rotation_of(const PlaneFit& base, const PlaneFit& target, double yaw_deg) {
  return levelling_rotation(base.normal).transpose() *
         Eigen::AngleAxisd(yaw_deg * ulc::kRadPerDeg, ulc::Vec3d::UnitZ()).toRotationMatrix() *
         levelling_rotation(target.normal);
}

/// An options problem, else empty.
inline std::string options_problem(const GroundVoteOptions& o) {
  if (!(o.voxel > 0.0 && o.max_translation >= 0.0 && o.max_range > 0.0 &&
        o.max_height > o.min_height && o.coarse_step_deg > 0.0 && o.fine_step_deg > 0.0 &&
        o.fine_step_deg <= o.coarse_step_deg && o.coarse_voxel >= o.voxel &&
        o.max_range / o.voxel < 1e5))
    return "invalid options (voxel, steps, ranges or heights)";
  if (!(o.base_ring_gap_deg >= 0.0 && o.base_ring_gap_deg <= 30.0))
    return "invalid options: base_ring_gap_deg must lie in [0, 30] deg";
  if (!(o.pose_tilt_deg > 0.0 && o.pose_tilt_deg <= 90.0 && o.pose_shift_voxels <= 20))
    return "invalid options: pose_tilt_deg must lie in (0, 90] deg and pose_shift_voxels in "
           "[0, 20]";
  // The fine grid's cells (one byte each): bounded, whatever the options ask.
  const double side = 2.0 * (o.max_range + o.max_translation + o.voxel) / o.voxel;
  if (side * side * (o.max_height - o.min_height) / o.voxel > 2e8)
    return "invalid options: the occupancy grid would exceed 200 MB (voxel too fine for the "
           "range and heights)";
  return {};
}

}  // namespace ground_vote_detail

/// One base cloud and target frame made ready to vote: levelled on their grounds, the target
/// thinned, the base's grids built. `problem` says why they cannot vote (then nothing else is
/// filled).
struct GroundVoteInput {
  std::string problem;
  PlaneFit base_plane;
  std::vector<ground_vote_detail::TargetGround> grounds;
  std::vector<OccupancyGrid> grids;  ///< coarse, fine
  /// Fine voxels a base frame's rays crossed before their hit (add_free_space), empty when none
  /// was given: a pose that puts target points there contradicts what the base saw.
  std::vector<OccupancyGrid> free;
};

template <class BaseCloud, class TargetCloud>
GroundVoteInput prepare_ground_vote(const BaseCloud& base, const TargetCloud& target,
                                    const GroundVoteOptions& o = {}) {
  using namespace ground_vote_detail;
  GroundVoteInput in;
  if (std::string why = options_problem(o); !why.empty()) return in.problem = why, in;
  const std::vector<PlaneFit> base_planes = largest_planes(base, 1, o.min_plane_points, o.plane);
  if (base_planes.empty()) return in.problem = "the base shows no ground plane", in;
  in.base_plane = base_planes.front();
  for (const PlaneFit& p : largest_planes(target, o.target_planes, o.min_plane_points, o.plane))
    if (std::fabs(p.offset - in.base_plane.offset) <= o.max_height_difference)
      in.grounds.push_back({p, one_per_voxel(levelled(target, p, o), o.voxel, o.max_points)});
  if (in.grounds.empty())
    return in.problem = "none of the target's largest planes lies at the base's ground's height",
           in;
  // Grounds with too few points above them do not vote (a wall taken for the ground with a
  // handful of points beside it would win on its share).
  std::size_t most = 0;
  for (const TargetGround& g : in.grounds) most = std::max(most, g.points.size());
  if (most < o.min_points)
    return in.problem = "only " + std::to_string(most) + " target voxels above the ground (" +
                        std::to_string(o.min_points) + " needed)",
           in;
  const std::vector<ulc::Vec3d> base_points = levelled(base, in.base_plane, o);
  in.grids.push_back(base_grid(base_points, o.coarse_voxel, o));
  in.grids.push_back(base_grid(base_points, o.voxel, o));
  return in;
}

/// Marks the fine voxels `base_frame`'s rays crossed (from its origin to one voxel short of
/// each hit, at most max_points * 20 rays, every k-th) as free. `base_frame` is a raw frame of
/// the base in the frame the input's base cloud is in (its origin the sensor's).
template <class Cloud>
void add_free_space(GroundVoteInput& in, const Cloud& base_frame, const GroundVoteOptions& o) {
  if (!in.problem.empty()) return;
  const ulc::Mat3d L = levelling_rotation(in.base_plane.normal);
  OccupancyGrid free(o.voxel, o.max_range + o.max_translation + o.voxel, o.min_height,
                     o.max_height);
  const ulc::Vec3d origin(0.0, 0.0, in.base_plane.offset);
  const std::size_t n = ulc::traits::size(base_frame),
                    rays = 20 * std::max<std::size_t>(1, o.max_points);
  const std::size_t stride = std::max<std::size_t>(1, (n + rays - 1) / rays);
  for (std::size_t i = 0; i < n; i += stride) {
    const ulc::Vec3d p = ulc::traits::point(base_frame, i).template cast<double>();
    if (!p.allFinite() || p.norm() < o.plane.min_range) continue;
    const ulc::Vec3d q = ground_vote_detail::levelled_point(L, in.base_plane, p);
    const double length = std::min((q - origin).norm(), o.max_range + o.max_translation);
    const ulc::Vec3d dir = (q - origin).normalized();
    for (double t = 0.5 * o.voxel; t < length - o.voxel; t += 0.5 * o.voxel)
      free.mark(origin + t * dir);
  }
  in.free.push_back(std::move(free));
}

namespace ground_vote_detail {

/// The pose (R_base_target, t_base_target) a levelled peak stands for.
inline GroundPose pose_of(const GroundVoteInput& in, const Peak& p) {
  const TargetGround& g = in.grounds[p.plane];
  const ulc::Vec3d shift(p.tx, p.ty, g.plane.offset - in.base_plane.offset);
  return {rotation_of(in.base_plane, g.plane, p.yaw_deg),
          levelling_rotation(in.base_plane.normal).transpose() * shift};
}

/// Each voting ground's coarse sweep, its best peaks refined, with the share of its points.
inline std::vector<std::pair<Peak, double>> refined_peaks(const GroundVoteInput& in,
                                                          const GroundVoteOptions& o) {
  std::vector<std::pair<Peak, double>> refined;
  const auto steps = static_cast<std::size_t>(std::ceil(360.0 / o.coarse_step_deg));
  for (std::size_t j = 0; j < in.grounds.size(); ++j) {
    const TargetGround& g = in.grounds[j];
    if (g.points.size() < o.min_points) continue;
    for (Peak p : best_peaks(sweep(in.grids[0], g.points, 0.0, o.coarse_step_deg, steps, o),
                             o.peaks_per_plane, o.peak_separation_deg)) {
      p.plane = j;
      const Peak f = refine(in.grids[1], g, p, o);
      refined.emplace_back(f, double(f.votes) / double(g.points.size()));
    }
  }
  return refined;
}

}  // namespace ground_vote_detail

/// Sets a vote's verdict from its score and margin: ok when the score reaches min_score and
/// the margin min_margin, else the reason it is not, after `prefix` (e.g. where it was taken).
inline void judge_vote(GroundVoteResult& r, const GroundVoteOptions& o,
                       const std::string& prefix = "") {
  r.reason.clear();
  if (!(r.score >= o.min_score))
    r.reason = prefix + "only " + std::to_string(int(100.0 * r.score)) +
               " % of the target's votes land on the base's surfaces";
  else if (!(r.margin >= o.min_margin))
    r.reason = prefix + "ambiguous: a rotation more than " +
               std::to_string(int(o.margin_separation_deg)) + " deg away gathers 1/" +
               std::to_string(r.margin).substr(0, 4) + " of the best one's votes";
  r.ok = r.reason.empty();
}

/// The best share of votes of a prepared input near a given pose: the target ground whose
/// normal the pose turns within pose_tilt_deg of the base's, yaws within one coarse step and
/// shifts within pose_shift_voxels of the pose's (so that poses found on another frame, on
/// their own grid, are scored at their best here). 0 when the input cannot vote.
inline double pose_share(const GroundVoteInput& in, const GroundPose& pose,
                         const GroundVoteOptions& o) {
  using namespace ground_vote_detail;
  if (!in.problem.empty()) return 0.0;
  const ulc::Mat3d Lb = levelling_rotation(in.base_plane.normal);
  const ulc::Vec3d shift = Lb * pose.translation;
  const auto half = static_cast<int>(std::floor(o.coarse_step_deg / o.fine_step_deg));
  double best = 0.0;
  for (const TargetGround& g : in.grounds) {
    if (g.points.size() < o.min_points ||
        std::acos(std::clamp((pose.rotation * g.plane.normal).dot(in.base_plane.normal), -1.0,
                             1.0)) > o.pose_tilt_deg * ulc::kRadPerDeg)
      continue;
    const ulc::Mat3d Z = Lb * pose.rotation * levelling_rotation(g.plane.normal).transpose();
    const double yaw = std::atan2(Z(1, 0), Z(0, 0)) / ulc::kRadPerDeg;
    for (int k = -half; k <= half; ++k) {
      const Peak p = best_shift_near(in.grids[1], g.points, yaw + k * o.fine_step_deg, shift.x(),
                                     shift.y(), static_cast<int>(o.pose_shift_voxels),
                                     in.free.empty() ? nullptr : &in.free.front());
      best = std::max(best, double(p.votes) / double(g.points.size()));
    }
  }
  return best;
}

/// R_base_target from a prepared input (see the conventions above).
inline GroundVoteResult ground_vote(const GroundVoteInput& in, const GroundVoteOptions& o = {}) {
  using namespace ground_vote_detail;
  GroundVoteResult r;
  if (!in.problem.empty()) return r.reason = in.problem, r;
  const std::vector<std::pair<Peak, double>> refined = refined_peaks(in, o);
  if (refined.empty()) return r.reason = "no target point above the ground lands on the base", r;
  std::size_t win = 0;
  for (std::size_t k = 1; k < refined.size(); ++k)
    if (refined[k].second > refined[win].second) win = k;
  const Peak& w = refined[win].first;
  const TargetGround& g = in.grounds[w.plane];
  const GroundPose best = pose_of(in, w);
  r.rotation = best.rotation;
  r.translation = best.translation;
  r.score = refined[win].second;
  r.points = g.points.size();
  r.target_plane = w.plane;
  r.base_height = in.base_plane.offset;
  r.target_height = g.plane.offset;
  r.base_ring_gap_deg = o.base_ring_gap_deg;
  double rival = 0.0;
  for (const auto& [p, share] : refined) {
    r.peaks.push_back(pose_of(in, p));
    if (ulc::rotation_error_rad(r.peaks.back().rotation, r.rotation) / ulc::kRadPerDeg >
        o.margin_separation_deg)
      rival = std::max(rival, share);
  }
  r.margin = rival > 0.0 ? r.score / rival : std::numeric_limits<double>::infinity();
  judge_vote(r, o);
  return r;
}

/// R_base_target from the base cloud and one target frame (see the conventions above).
template <class BaseCloud, class TargetCloud>
GroundVoteResult ground_vote(const BaseCloud& base, const TargetCloud& target,
                             const GroundVoteOptions& o = {}) {
  return ground_vote(prepare_ground_vote(base, target, o), o);
}

}  // namespace terra
