// The hierarchy of one LiDAR (paper Sec. "Pose Refinement by Hierarchical Optimization", after
// HBA): frames are grouped in windows of w; each window's BA (window_ba.hpp) refines its frames
// relative to its first one, and the window's frames, merged in the first frame's coordinates,
// become one frame (a submap) of the next layer. Layers repeat up to `layers`.
//
// Conventions this header owns:
//   - Input: one cloud per frame (points in the frame's body frame, already deskewed) and
//     T_world_frame per frame. Members of layer l are layer-0 frames' subtrees: member k of layer
//     l covers the contiguous frames [begin, end) and is ANCHORED at frame `begin`: its pose is
//     that frame's pose, its cloud is the subtree's points in that frame's coordinates. So a
//     submap needs no variable of its own in the pose graph; its factors tie anchor frames.
//   - Windows are consecutive runs of w members (the last run may be shorter; a run of one is
//     carried up unchanged). Windows of a layer run as TBB tasks, each into its own slot, in
//     batches of a few per thread with the caller's progress between them
//     (ulc/core/batched_for.hpp); their outcomes are absorbed serially, in window order.
//   - After a window's BA, every frame of member k's subtree moves with it:
//     T <- T_k,new T_k,old^-1 T. `poses` holds the result of all layers.
//   - Each window with a usable BA yields one relative-pose factor per member k >= 1: from the
//     anchor of member 0 to the anchor of member k, Z = T_0^-1 T_k, information = the inverse of
//     the k-th 6x6 block of (H / (2 sigma^2))^-1 (H the BA Hessian without the gauge block,
//     sigma^2 its noise estimate), i.e. the marginal information of that relative pose.
//   - Submap clouds are voxel-downsampled (submap_voxel) to bound the upper layers' work.
//   - The top layer's windows share no member: boundary_bridges.hpp can tie them afterwards
//     (one more BA per boundary, over the members on both sides).
//   - Continuous-time layer 0 (optional: the caller passes each frame's SweepParts, views into
//     the frame's points, which hold them part after part: ulc/core/point_span.hpp): the
//     window's BA is sweep_ba.hpp's, whose variables are the members' poses plus, with
//     end_knot and a next frame, that frame's pose (where the last sweep ends); the submap
//     places each part at its own pose. The next frame's estimate is dropped, or kept as one
//     more factor from the window's anchor (end_knot_factor).
//   - Nothing here throws (a throwing progress hook passes through) or prints; the same results
//     for any number of threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "hots/options.hpp"
#include "hots/pose_graph.hpp"
#include "hots/sweep_ba.hpp"
#include "hots/window_ba.hpp"
#include "ulc/core/batched_for.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/point_span.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace hots {

/// One frame's sweep for a continuous-time layer 0: its points in parts by time (views into the
/// frame's points, which must outlive them), each part's mean fraction of the frame period, and
/// the motion the points were deskewed with.
template <typename S>
struct SweepParts {
  std::vector<ulc::PointSpan<S>> parts;
  std::vector<double> fraction;
  Isometry3d deskew = Isometry3d::Identity();
};

/// A relative-pose factor between two layer-0 frames, from a window's BA.
struct HierarchyFactor {
  std::size_t from = 0;  ///< anchor frame of the window's first member
  std::size_t to = 0;    ///< anchor frame of member k
  Isometry3d measured = Isometry3d::Identity();
  Mat6d information = Mat6d::Zero();
  int layer = 0;
};

/// One member of a layer: a subtree of frames, anchored at its first frame.
template <typename S>
struct HierarchyMember {
  std::size_t begin = 0, end = 0;   ///< layer-0 frames [begin, end); the anchor is `begin`
  std::vector<ulc::Vec3<S>> cloud;  ///< in the anchor's coordinates (empty at layer 0)
};

template <typename S>
struct HierarchyResult {
  std::vector<Isometry3d> poses;  ///< T_world_frame after all layers
  std::vector<HierarchyFactor> factors;
  /// members[l] = layer l's members (layer 0: one per frame, clouds not copied).
  std::vector<std::vector<HierarchyMember<S>>> members;
  std::size_t windows = 0;
  std::size_t failed_windows = 0;  ///< BA unusable: no factor, poses unchanged
  std::size_t planes = 0;          ///< over all windows
};

namespace hierarchy_detail {

/// Marginal information of each member k >= 1's relative pose from a window's BA.
inline std::vector<Mat6d> marginal_information(const WindowBaResult& ba, double min_sigma) {
  const Eigen::Index n = ba.hessian.rows();
  std::vector<Mat6d> out;
  if (n < 12) return out;
  const double sigma_sq = std::max(ba.noise_variance, min_sigma * min_sigma);
  const Eigen::MatrixXd H = ba.hessian.bottomRightCorner(n - 6, n - 6) / (2.0 * sigma_sq);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(0.5 * (H + H.transpose()));
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return out;
  const Eigen::MatrixXd cov = ldlt.solve(Eigen::MatrixXd::Identity(n - 6, n - 6));
  if (!cov.allFinite()) return out;
  for (Eigen::Index k = 0; k + 6 <= n - 6; k += 6) {
    const Mat6d block = cov.block<6, 6>(k, k);
    const Eigen::LDLT<Mat6d> inv(0.5 * (block + block.transpose()));
    if (inv.info() != Eigen::Success || !(inv.vectorD().minCoeff() > 0.0)) return {};
    Mat6d info = inv.solve(Mat6d::Identity());
    out.push_back(0.5 * (info + info.transpose()));
  }
  return out;
}

/// The sweep window of layer-0 frames [first, last): every non-empty part of their sweeps,
/// and the next frame as the last sweep's end knot when asked for and there is one.
template <typename S>
SweepWindow<ulc::PointSpan<S>> sweep_window(const std::vector<SweepParts<S>>& sweeps,
                                            std::size_t first, std::size_t last, bool end_knot) {
  SweepWindow<ulc::PointSpan<S>> sw;
  for (std::size_t m = first; m < last; ++m) {
    const SweepParts<S>& sp = sweeps[m];
    sw.deskew.push_back(sp.deskew);
    for (std::size_t j = 0; j < sp.parts.size() && j < sp.fraction.size(); ++j) {
      if (sp.parts[j].empty()) continue;
      sw.clouds.push_back(&sp.parts[j]);
      sw.sweep.push_back(m - first);
      sw.fraction.push_back(sp.fraction[j]);
    }
  }
  if (end_knot && last < sweeps.size()) sw.deskew.push_back(sweeps[last].deskew);
  return sw;
}

/// What one window of a layer yields: its BA, the marginal information of its members'
/// relative poses (empty: no usable BA, the members keep their poses), its submap for the next
/// layer and, at a continuous layer 0, the factor to its end knot.
template <typename S>
struct WindowOutcome {
  WindowBaResult ba;
  bool ran = false;
  std::vector<Mat6d> information;
  HierarchyMember<S> submap;
  std::vector<HierarchyFactor> end_factor;
};

/// A window's members: their clouds (frames at layer 0, submaps above) and current poses.
template <typename S>
struct WindowMembers {
  std::vector<const std::vector<ulc::Vec3<S>>*> clouds;
  std::vector<Isometry3d> poses;
};

/// The submap's entries (the members, or at a continuous layer 0 the parts of their sweeps),
/// each entry's member and each entry's pose after the BA.
template <typename S>
struct WindowEntries {
  std::vector<ulc::PointSpan<S>> spans;
  std::vector<std::size_t> member;
  std::vector<Isometry3d> poses;
};

/// One entry per member, its whole cloud (poses left for the caller).
template <typename S>
WindowEntries<S> member_entries(const WindowMembers<S>& wm) {
  WindowEntries<S> e;
  for (std::size_t m = 0; m < wm.clouds.size(); ++m) {
    e.spans.emplace_back(*wm.clouds[m]);
    e.member.push_back(m);
  }
  return e;
}

/// The window's BA (rigid, or over its sweeps' parts at a continuous layer 0) into o, and the
/// submap's entries with their poses.
template <typename S>
WindowEntries<S> window_ba_entries(const WindowMembers<S>& wm,
                                   const std::vector<SweepParts<S>>* sweeps, std::size_t first,
                                   std::size_t last, const Isometry3d* next_pose,
                                   const HierarchyOptions& options, WindowOutcome<S>& o) {
  WindowEntries<S> e;
  std::size_t knots = wm.clouds.size();
  if (sweeps) {
    const SweepWindow<ulc::PointSpan<S>> sw = sweep_window(*sweeps, first, last, options.end_knot);
    std::vector<Isometry3d> knot_poses = wm.poses;
    if (sw.deskew.size() > wm.clouds.size()) knot_poses.push_back(*next_pose);
    knots = knot_poses.size();
    SweepBaResult sr = sweep_window_ba(sw, knot_poses, options.ba);
    o.ba = std::move(sr.ba);
    for (const ulc::PointSpan<S>* part : sw.clouds) e.spans.push_back(*part);
    e.member = sw.sweep;
    e.poses = std::move(sr.entry_poses);
  } else {
    e = member_entries(wm);
    o.ba = window_ba(wm.clouds, wm.poses, options.ba);
    e.poses = o.ba.poses;
  }
  const bool usable = o.ba.ok() || o.ba.status == WindowBaStatus::not_converged;
  if (usable) o.information = marginal_information(o.ba, options.min_sigma);
  if (!usable || o.information.size() + 1 != knots) {
    o.information.clear();
    return e;
  }
  if (knots > wm.clouds.size() && options.end_knot_factor) {
    HierarchyFactor f;  // to the next frame, where the last sweep ends
    f.from = first;
    f.to = last;
    f.measured = o.ba.poses[0].inverse() * o.ba.poses.back();
    f.information = o.information.back();
    f.layer = 0;
    o.end_factor.push_back(f);
  }
  o.information.resize(wm.clouds.size() - 1);
  o.ba.poses.resize(wm.clouds.size());
  return e;
}

/// Every entry's points in the first member's coordinates, voxel-downsampled.
template <typename S>
std::vector<ulc::Vec3<S>> merged_submap(const WindowEntries<S>& e, const Isometry3d& first_pose,
                                        double voxel) {
  const Isometry3d first_inv = first_pose.inverse();
  std::size_t total = 0;
  for (const auto& span : e.spans) total += span.size();
  std::vector<ulc::Vec3<S>> merged;
  merged.reserve(total);
  for (std::size_t k = 0; k < e.spans.size(); ++k) {
    const Isometry3d T = first_inv * e.poses[k];
    for (const auto& p : e.spans[k])
      merged.push_back((T * p.template cast<double>()).template cast<S>());
  }
  const auto down = ulc::voxel_downsample(merged, voxel);
  return down.ok() ? down.cloud.points : merged;
}

/// Window k of layer l: members [k w, k w + w) of `layer`, at the poses in `poses`.
template <typename S>
WindowOutcome<S> run_window(const std::vector<std::vector<ulc::Vec3<S>>>& frames,
                            const std::vector<SweepParts<S>>* sweeps,
                            const std::vector<HierarchyMember<S>>& layer, int l, std::size_t k,
                            const std::vector<Isometry3d>& poses, const HierarchyOptions& options) {
  const std::size_t w = options.window;
  const std::size_t first = k * w, last = std::min(first + w, layer.size());
  WindowMembers<S> wm;
  for (std::size_t m = first; m < last; ++m) {
    wm.clouds.push_back(l == 0 ? &frames[layer[m].begin] : &layer[m].cloud);
    wm.poses.push_back(poses[layer[m].begin]);
  }
  WindowOutcome<S> o;
  WindowEntries<S> e;
  if (wm.clouds.size() >= 2) {
    o.ran = true;
    const bool continuous = l == 0 && sweeps;
    const Isometry3d* next = last < poses.size() ? &poses[last] : nullptr;
    e = window_ba_entries(wm, continuous ? sweeps : nullptr, first, last, next, options, o);
  } else {
    e = member_entries(wm);
  }
  if (o.information.empty()) {  // no usable BA: keep the start
    o.ba.poses = wm.poses;
    e.poses.clear();
    for (std::size_t m : e.member) e.poses.push_back(wm.poses[m]);
  }
  o.submap.begin = layer[first].begin;
  o.submap.end = layer[last - 1].end;
  o.submap.cloud = merged_submap(e, o.ba.poses[0], options.submap_voxel);
  return o;
}

/// Window k's outcome into out, in window order: its members' subtrees moved, its factors
/// collected (see the header comment).
template <typename S>
void absorb_window(const std::vector<HierarchyMember<S>>& layer, int l, std::size_t k,
                   std::size_t w, const WindowOutcome<S>& o, HierarchyResult<S>& out) {
  const std::size_t first = k * w, last = std::min(first + w, layer.size());
  if (o.ran) {
    ++out.windows;
    out.planes += o.ba.planes;
    if (o.information.empty()) ++out.failed_windows;
  }
  for (std::size_t m = first; m < last; ++m) {
    const Isometry3d delta = o.ba.poses[m - first] * out.poses[layer[m].begin].inverse();
    for (std::size_t f = layer[m].begin; f < layer[m].end; ++f) out.poses[f] = delta * out.poses[f];
    if (m > first && !o.information.empty()) {
      HierarchyFactor factor;
      factor.from = layer[first].begin;
      factor.to = layer[m].begin;
      factor.measured = o.ba.poses[0].inverse() * o.ba.poses[m - first];
      factor.information = o.information[m - first - 1];
      factor.layer = l;
      out.factors.push_back(factor);
    }
  }
  if (!o.information.empty())
    out.factors.insert(out.factors.end(), o.end_factor.begin(), o.end_factor.end());
}

/// Windows over all layers for `frames` frames: what a progress fraction counts.
inline std::size_t total_windows(std::size_t frames, const HierarchyOptions& options) {
  std::size_t total = 0;
  for (int l = 0; l < options.layers && frames >= 2; ++l) {
    frames = (frames + options.window - 1) / options.window;
    total += frames;
  }
  return total;
}

}  // namespace hierarchy_detail

/// Builds and optimises the hierarchy of one LiDAR (see the header comment). progress
/// (optional) gets the fraction of windows done, on the calling thread, every few windows.
template <typename S>
HierarchyResult<S> build_hierarchy(const std::vector<std::vector<ulc::Vec3<S>>>& frames,
                                   const std::vector<Isometry3d>& poses,
                                   const HierarchyOptions& options = {},
                                   const std::vector<SweepParts<S>>* sweeps = nullptr,
                                   const ulc::StepProgress& progress = {}) {
  namespace d = hierarchy_detail;
  HierarchyResult<S> out;
  out.poses = poses;
  if (frames.size() != poses.size() || options.window < 2 || options.layers < 1) return out;
  if (sweeps && sweeps->size() != frames.size()) sweeps = nullptr;
  const double total =
      static_cast<double>(std::max<std::size_t>(d::total_windows(frames.size(), options), 1));
  std::size_t done_before = 0;
  std::vector<HierarchyMember<S>> layer(frames.size());
  for (std::size_t f = 0; f < frames.size(); ++f) {
    layer[f].begin = f;
    layer[f].end = f + 1;
  }
  for (int l = 0; l < options.layers && layer.size() >= 2; ++l) {
    const std::size_t w = options.window;
    const std::size_t n_windows = (layer.size() + w - 1) / w;
    std::vector<d::WindowOutcome<S>> outcomes(n_windows);
    ulc::parallel_for_in_batches(
        n_windows, ulc::default_batch_size(),
        [&](std::size_t k) {
          outcomes[k] = d::run_window(frames, sweeps, layer, l, k, out.poses, options);
        },
        [&](std::size_t done) {
          if (progress) progress(static_cast<double>(done_before + done) / total);
        });
    done_before += n_windows;
    std::vector<HierarchyMember<S>> next;
    for (std::size_t k = 0; k < n_windows; ++k) {
      d::absorb_window(layer, l, k, w, outcomes[k], out);
      next.push_back(std::move(outcomes[k].submap));
    }
    out.members.push_back(std::move(layer));
    layer = std::move(next);
  }
  if (!layer.empty()) out.members.push_back(std::move(layer));
  return out;
}

}  // namespace hots
