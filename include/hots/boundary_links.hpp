// Boundary links: each top-layer submap of one LiDAR registered to the next one.
//
// Conventions this header owns:
//   - The hierarchy's top-layer submaps share no BA window (hierarchy.hpp), so something else
//     must tie each to the next. The odometry's step across the boundary (last frame of one
//     submap to the first of the next) did, but it is only as good as those two frames: one
//     odometry glitch there (a speed bump's pitch, a turn's entry: frames the constant-velocity
//     deskew gets wrong) was locked into the graph and tilted the rest of the drive (60 s 64-32,
//     seed 2: 0.9 m of height error; docs/experiments/boundary_registration.md). Two whole
//     submaps overlap over tens of metres and register to each other far more reliably than
//     two frames.
//   - Link m: submap m + 1's cloud (source) to submap m's planes (target), from the current
//     relative pose of their anchors (the odometry's across the boundary, the BA's inside), by
//     register_clouds (cross_links.hpp): Z = T_anchor_m^-1 T_anchor_m+1 with the
//     registration's information. CrossLink::frame_a and frame_b are the two anchor frames.
//   - Optionally both clouds are cropped to a ball of `radius` around the boundary (the next
//     submap's anchor): a top-layer submap spans a hundred metres or more of road and the next
//     one overlaps it only near their common boundary, so whole submaps leave most source
//     points without a partner and can fail CrossLinkOptions::min_inlier_ratio (60 s 64-32:
//     4-6 of 8 boundaries registered). A 40 m crop registered all 8 but did not make the
//     trajectory better (best-aligned ATE, seeds 1-3: 2.06 / 3.96 / 2.43 cm whole, 1.94 /
//     5.28 / 2.60 cm cropped; docs/experiments/boundary_registration.md), so the
//     default is no crop.
//   - Boundaries marked in `skip` (those a bridge BA already ties, boundary_bridges.hpp) are
//     not registered.
//   - A boundary whose registration is unusable (empty submaps at the ends, too few inliers)
//     gets no link; refine() then falls back to the odometry's step there.
//   - Registrations run as TBB tasks, one slot each; links are in boundary order. Nothing here
//     throws or prints.
#pragma once

#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hots/cross_links.hpp"
#include "hots/hierarchy.hpp"

namespace hots {

namespace boundary_detail {

/// The points of `cloud` within `radius` of `centre` (all of them when radius <= 0).
template <typename S>
std::vector<ulc::Vec3<S>> within(const std::vector<ulc::Vec3<S>>& cloud, const ulc::Vec3d& centre,
                                 double radius) {
  if (!(radius > 0.0)) return cloud;
  const ulc::Vec3<S> c = centre.cast<S>();
  const S r2 = static_cast<S>(radius * radius);
  std::vector<ulc::Vec3<S>> out;
  for (const auto& p : cloud)
    if ((p - c).squaredNorm() <= r2) out.push_back(p);
  return out;
}

}  // namespace boundary_detail

/// One entry per top-layer boundary (m, m + 1), empty where the registration was unusable.
template <typename S>
std::vector<std::optional<CrossLink>> boundary_links(
    const HierarchyResult<S>& h, const std::vector<std::vector<ulc::Vec3<S>>>& frames,
    const std::vector<Isometry3d>& poses, const CrossLinkOptions& options, double radius = 0.0,
    const std::vector<bool>* skip = nullptr) {
  if (h.members.empty() || h.members.back().size() < 2) return {};
  const auto& top = h.members.back();
  const bool frames_are_members = h.members.size() == 1;  // no BA layer ran: frames on top
  const auto stages = ulc::coarse_to_fine_stages(options.gate);
  std::vector<std::optional<CrossLink>> out(top.size() - 1);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, out.size(), 1),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t m = r.begin(); m != r.end(); ++m) {
          if (skip && m < skip->size() && (*skip)[m]) continue;
          const auto& first = top[m];
          const auto& second = top[m + 1];
          const auto& target = frames_are_members ? frames[first.begin] : first.cloud;
          const auto& source = frames_are_members ? frames[second.begin] : second.cloud;
          const Isometry3d initial = poses[first.begin].inverse() * poses[second.begin];
          // The boundary is the next anchor's origin: at initial.translation() in the target's
          // frame, at the origin in the source's.
          out[m] = register_clouds(boundary_detail::within(target, initial.translation(), radius),
                                   boundary_detail::within(source, ulc::Vec3d::Zero(), radius),
                                   initial, options, stages);
          if (!out[m]) continue;
          out[m]->frame_a = first.begin;
          out[m]->frame_b = second.begin;
          out[m]->layer = static_cast<int>(h.members.size()) - 1;
        }
      });
  return out;
}

}  // namespace hots
