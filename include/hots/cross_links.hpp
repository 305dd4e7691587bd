// Cross-LiDAR links: the two hierarchies (hierarchy.hpp) are tied by registering, at every
// layer, each submap of LiDAR b to the submap of LiDAR a nearest in time (paper Sec. "Pose
// Refinement by Hierarchical Optimization": "linked through the registration of different
// layer submaps"), starting from their current poses, i.e. through the current extrinsic.
//
// Conventions this header owns:
//   - Both LiDARs' poses are T_world_frame in ONE world frame. A member's time is its anchor
//     frame's timestamp; b's times are moved to a's clock with t_a = t_b + time_offset_s.
//   - The registration (ulc point_to_plane, coarse to fine) estimates Z = T_anchor_a^-1
//     T_anchor_b: source = b's member cloud, target = a's member cloud with per-point planes.
//     Its information is the registration's Hessian (left perturbation in a's anchor frame,
//     exactly the pose-graph residual's tangent) over sigma^2, sigma = max(rmse, min_sigma).
//   - Both clouds are voxel-downsampled before the registration (source_voxel for b's,
//     target_voxel for a's planes): a few thousand well-spread points fix a 6-DoF pose, and
//     the link's cost (a's kd-trees and normals, b's matches) is linear in them. Measured on
//     bench_hots (64-32): 2.3x faster and no less accurate than the 0.1 m frames; the
//     information (Hessian of fewer points) is smaller, which weights links less against the
//     windows' BA; accuracy did not suffer from that (scaling it back up was worse).
//   - A link is kept when the registration is ok and its inlier ratio >= min_inlier_ratio
//     (register_clouds, also used by boundary_links.hpp). CrossLinkStats also counts the
//     registrations that converged but were not kept, and their median inlier ratio: what
//     tells "the views overlap too little" from "the links refuse the extrinsic".
//   - The inlier ratio is also measured over b's points within a's reach only (the farthest of
//     a's thinned points from its anchor, plus the first stage's gate): a's surfaces cannot
//     hold what lies beyond it, so those points say nothing of the extrinsic. HOTS judges by
//     it on a second look (refine_steps.hpp, link_lidars) when the plain ratio keeps too few
//     links to judge: flicar-lift's Avia (450 m) against its OS0-128 base (50 m), 10 s, seed
//     1, from the truth: median ratio 0.07 over all points (none kept), 0.18 within reach (15
//     kept, all agreeing); from starts 2 m, 3 deg or 2 deg off, 13-14 kept, none agreeing
//     (docs/experiments/cross_links_within_reach.md).
//   - A kept link agrees with the extrinsic when the registration moved less than
//     agree_rotation_rad and agree_translation_m from its start (CrossLink::moved_*): the start
//     is the prediction of the odometry's poses and the current extrinsic, good to a few
//     centimetres and a tenth of a degree when the extrinsic is right. Measured on the
//     seven-LiDAR rig's Tele (60 s): from the true extrinsic 35 of its 50 kept links
//     moved less than 1 deg and 1 m (the rest converged elsewhere in the narrow cone, 1.4-8.4
//     deg); from the wrong one JEEP accepted (11.3 deg / 5.2 m off) all 27 kept links moved
//     1.6-14.8 deg, none agreed. hots.hpp's trust rule counts agreeing links.
//   - Registrations run as TBB tasks, one slot each, in batches with the caller's progress
//     between them (ulc/core/batched_for.hpp); they and the kept links are in (layer, a member)
//     order.
//     Nothing here throws (a throwing progress hook passes through) or prints.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "hots/hierarchy.hpp"
#include "hots/options.hpp"
#include "hots/refine_statistics.hpp"
#include "ulc/core/batched_for.hpp"
#include "ulc/core/median.hpp"
#include "ulc/core/nearest_time.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/registration_target.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace hots {

struct CrossLink {
  std::size_t frame_a = 0, frame_b = 0;  ///< anchor frames
  Isometry3d measured = Isometry3d::Identity();
  Mat6d information = Mat6d::Zero();
  int layer = 0;
  double rmse = 0.0;
  double moved_rad = 0.0, moved_m = 0.0;  ///< how far the registration moved from its start
};

struct CrossLinkStats {
  std::size_t attempted = 0;
  std::size_t kept = 0;
  std::size_t agreeing = 0;   ///< kept links that moved less than the agree_* bounds
  std::size_t converged = 0;  ///< registrations that converged, kept or not
  /// Weak links: converged, not kept, inlier ratio >= weak_inlier_ratio; and of those the ones
  /// within the agree_* bounds (docs/experiments/tele_cross_links.md).
  std::size_t weak = 0, weak_agreeing = 0;
  /// Median inlier ratio of the converged registrations (0 when none): how much of b's view
  /// lies on a's surfaces, against CrossLinkOptions::min_inlier_ratio.
  double inlier_ratio_median = 0.0;
  std::vector<CrossLinkRecord> records;  ///< every registration, in (layer, a member) order
};

/// One registration of b's cloud to a's planes before the keep rule: whether it converged, its
/// inlier ratio over all of b's points and over those within a's reach, and the link it
/// measured (meaningful when converged).
struct LinkRegistration {
  bool converged = false;
  double inlier_ratio = 0.0;
  double inlier_ratio_in_reach = 0.0;
  CrossLink link;
  double ratio(bool within_reach) const {
    return within_reach ? inlier_ratio_in_reach : inlier_ratio;
  }
  bool kept(const CrossLinkOptions& options, bool within_reach = false) const {
    return converged && ratio(within_reach) >= options.min_inlier_ratio;
  }
};

/// Whether a link moved less than the agree_* bounds from its start (see the conventions).
inline bool agrees(const CrossLink& link, const CrossLinkOptions& options) {
  return link.moved_rad < options.agree_rotation_rad && link.moved_m < options.agree_translation_m;
}

namespace cross_link_detail {

/// The members of a's layer l that get a link: every one, or every layer0_stride-th at layer 0.
inline std::vector<std::size_t> chosen_members(std::size_t members, std::size_t l,
                                               const CrossLinkOptions& options) {
  const std::size_t stride = l == 0 ? std::max<std::size_t>(options.layer0_stride, 1) : 1;
  std::vector<std::size_t> chosen;
  for (std::size_t i = 0; i < members; i += stride) chosen.push_back(i);
  return chosen;
}

/// The cloud voxel-downsampled into `storage` when voxel > 0 and that works; else the cloud.
template <typename S>
const std::vector<ulc::Vec3<S>>& thinned(const std::vector<ulc::Vec3<S>>& cloud, double voxel,
                                         std::vector<ulc::Vec3<S>>& storage) {
  if (!(voxel > 0.0)) return cloud;
  auto down = ulc::voxel_downsample(cloud, voxel);
  if (!down.ok()) return cloud;
  storage = std::move(down.cloud.points);
  return storage;
}

/// a's reach: the distance of its farthest point from its anchor.
template <typename S>
double reach_of(const std::vector<ulc::Vec3<S>>& cloud) {
  double reach = 0.0;
  for (const auto& p : cloud) reach = std::max(reach, static_cast<double>(p.norm()));
  return reach;
}

/// How many of b's points land within `reach` of a's anchor at the registered pose.
template <typename S>
std::size_t count_within(const std::vector<ulc::Vec3<S>>& source, const Isometry3d& pose,
                         double reach) {
  std::size_t n = 0;
  for (const auto& p : source) n += (pose * p.template cast<double>()).norm() <= reach ? 1 : 0;
  return n;
}

/// One registration counted into `stats` by the ratio the links are judged by; a converged
/// one's ratio appended to `ratios`.
inline void tally(const LinkRegistration& r, const CrossLinkOptions& options, bool within_reach,
                  CrossLinkStats& stats, std::vector<double>& ratios) {
  ++stats.attempted;
  stats.records.push_back({r.link.layer, r.converged, r.inlier_ratio, r.link.moved_rad,
                           r.link.moved_m, r.inlier_ratio_in_reach});
  if (!r.converged) return;
  ++stats.converged;
  ratios.push_back(r.ratio(within_reach));
  const std::size_t agreeing = agrees(r.link, options) ? 1 : 0;
  if (r.kept(options, within_reach)) {
    ++stats.kept;
    stats.agreeing += agreeing;
  } else if (r.ratio(within_reach) >= options.weak_inlier_ratio) {
    ++stats.weak;
    stats.weak_agreeing += agreeing;
  }
}

}  // namespace cross_link_detail

/// `source` registered to `target`'s planes from `initial` (both thinned first): whether it
/// converged, its inlier ratios and the measured T_target_source with its information (anchors
/// and layer are left for the caller).
template <typename S>
LinkRegistration register_link(const std::vector<ulc::Vec3<S>>& target,
                               const std::vector<ulc::Vec3<S>>& source, const Isometry3d& initial,
                               const CrossLinkOptions& options,
                               const std::vector<ulc::RegistrationOptions>& stages) {
  namespace d = cross_link_detail;
  LinkRegistration out;
  if (target.empty() || source.empty()) return out;
  std::vector<ulc::Vec3<S>> thin_target, thin_source;
  const auto& target_points = d::thinned(target, options.target_voxel, thin_target);
  const ulc::PlaneCloud<S> planes(target_points, options.planes);
  if (planes.empty()) return out;
  const auto& source_points = d::thinned(source, options.source_voxel, thin_source);
  const auto reg = ulc::register_point_to_plane(source_points, planes, initial, stages);
  if (!reg.ok()) return out;
  out.converged = true;
  out.inlier_ratio = reg.inlier_ratio();
  // An inlier lies within the gate of one of a's points, so the gate widens the reach.
  const std::size_t in_reach =
      d::count_within(source_points, reg.pose, d::reach_of(target_points) + options.gate);
  out.inlier_ratio_in_reach =
      in_reach ? static_cast<double>(reg.inliers) / static_cast<double>(in_reach) : 0.0;
  CrossLink& link = out.link;
  link.measured = reg.pose.template cast<double>();
  const double sigma = std::max(reg.rmse, options.min_sigma);
  link.information = reg.hessian / (sigma * sigma);
  link.rmse = reg.rmse;
  const Isometry3d moved = initial.inverse() * link.measured;
  link.moved_rad = Eigen::AngleAxisd(moved.linear()).angle();
  link.moved_m = moved.translation().norm();
  return out;
}

/// register_link's link when it is kept (converged, inlier ratio >= min_inlier_ratio), or
/// nothing when the registration is unusable.
template <typename S>
std::optional<CrossLink> register_clouds(const std::vector<ulc::Vec3<S>>& target,
                                         const std::vector<ulc::Vec3<S>>& source,
                                         const Isometry3d& initial, const CrossLinkOptions& options,
                                         const std::vector<ulc::RegistrationOptions>& stages) {
  LinkRegistration r = register_link(target, source, initial, options, stages);
  if (!r.kept(options)) return std::nullopt;
  return std::move(r.link);
}

/// Every cross-link registration, in (layer, a member) order (see the conventions), before
/// the keep rule. progress (optional) gets the fraction of registrations done, on the calling
/// thread, every few registrations.
template <typename S>
std::vector<LinkRegistration> cross_link_registrations(
    const HierarchyResult<S>& ha, const std::vector<std::vector<ulc::Vec3<S>>>& frames_a,
    const std::vector<double>& times_a, const std::vector<Isometry3d>& poses_a,
    const HierarchyResult<S>& hb, const std::vector<std::vector<ulc::Vec3<S>>>& frames_b,
    const std::vector<double>& times_b, const std::vector<Isometry3d>& poses_b,
    double time_offset_s, const CrossLinkOptions& options, const ulc::StepProgress& progress = {}) {
  namespace d = cross_link_detail;
  std::vector<LinkRegistration> registrations;
  const std::size_t layers = std::min(ha.members.size(), hb.members.size());
  const std::size_t first_layer = static_cast<std::size_t>(std::max(options.min_layer, 0));
  std::vector<std::vector<std::size_t>> chosen(layers);
  std::size_t total = 0, done_before = 0;
  for (std::size_t l = first_layer; l < layers; ++l) {
    if (ha.members[l].empty() || hb.members[l].empty()) continue;
    chosen[l] = d::chosen_members(ha.members[l].size(), l, options);
    total += chosen[l].size();
  }
  const auto stages = ulc::coarse_to_fine_stages(options.gate);
  for (std::size_t l = first_layer; l < layers; ++l) {
    const auto& ma = ha.members[l];
    const auto& mb = hb.members[l];
    if (chosen[l].empty()) continue;
    std::vector<double> tb;
    for (const auto& m : mb) tb.push_back(times_b[m.begin] + time_offset_s);
    std::vector<LinkRegistration> slot(chosen[l].size());
    ulc::parallel_for_in_batches(
        chosen[l].size(), ulc::default_batch_size(),
        [&](std::size_t c) {
          const auto& a = ma[chosen[l][c]];
          const auto& b = mb[ulc::nearest_time(tb, times_a[a.begin])];
          const auto& cloud_a = l == 0 ? frames_a[a.begin] : a.cloud;
          const auto& cloud_b = l == 0 ? frames_b[b.begin] : b.cloud;
          const Isometry3d initial = poses_a[a.begin].inverse() * poses_b[b.begin];
          slot[c] = register_link(cloud_a, cloud_b, initial, options, stages);
          slot[c].link.frame_a = a.begin;
          slot[c].link.frame_b = b.begin;
          slot[c].link.layer = static_cast<int>(l);
        },
        [&](std::size_t done) {
          if (progress)
            progress(static_cast<double>(done_before + done) / static_cast<double>(total));
        });
    done_before += chosen[l].size();
    registrations.insert(registrations.end(), slot.begin(), slot.end());
  }
  return registrations;
}

/// The links the keep rule keeps, judged by the inlier ratio over all of b's points or over
/// those within a's reach, in the registrations' order; `stats` counts them the same way.
inline std::vector<CrossLink> select_links(const std::vector<LinkRegistration>& registrations,
                                           const CrossLinkOptions& options, bool within_reach,
                                           CrossLinkStats& stats) {
  std::vector<CrossLink> links;
  stats = CrossLinkStats{};
  std::vector<double> ratios;  // the converged registrations' inlier ratios
  for (const auto& r : registrations) {
    cross_link_detail::tally(r, options, within_reach, stats, ratios);
    if (r.kept(options, within_reach)) links.push_back(r.link);
  }
  stats.inlier_ratio_median = ulc::median(std::move(ratios));
  return links;
}

}  // namespace hots
