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
//     carried up unchanged). Windows of a layer run as TBB tasks, each into its own slot.
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
//   - Nothing here throws or prints; the same results for any number of threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hots/options.hpp"
#include "hots/pose_graph.hpp"
#include "hots/sweep_ba.hpp"
#include "hots/window_ba.hpp"
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

}  // namespace hierarchy_detail

/// Builds and optimises the hierarchy of one LiDAR (see the header comment).
template <typename S>
HierarchyResult<S> build_hierarchy(const std::vector<std::vector<ulc::Vec3<S>>>& frames,
                                   const std::vector<Isometry3d>& poses,
                                   const HierarchyOptions& options = {},
                                   const std::vector<SweepParts<S>>* sweeps = nullptr) {
  using Cloud = std::vector<ulc::Vec3<S>>;
  HierarchyResult<S> out;
  out.poses = poses;
  if (frames.size() != poses.size() || options.window < 2 || options.layers < 1) return out;
  if (sweeps && sweeps->size() != frames.size()) sweeps = nullptr;

  std::vector<HierarchyMember<S>> layer(frames.size());
  for (std::size_t f = 0; f < frames.size(); ++f) {
    layer[f].begin = f;
    layer[f].end = f + 1;
  }
  for (int l = 0; l < options.layers && layer.size() >= 2; ++l) {
    const std::size_t w = options.window;
    const std::size_t n_windows = (layer.size() + w - 1) / w;
    struct Outcome {
      WindowBaResult ba;
      bool ran = false;
      std::vector<Mat6d> information;
      HierarchyMember<S> submap;
      std::vector<HierarchyFactor> end_factor;  ///< to the end knot (continuous layer 0)
    };
    std::vector<Outcome> outcomes(n_windows);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n_windows, 1),
        [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t k = r.begin(); k != r.end(); ++k) {
            const std::size_t first = k * w, last = std::min(first + w, layer.size());
            std::vector<const Cloud*> clouds;
            std::vector<Isometry3d> member_poses;
            for (std::size_t m = first; m < last; ++m) {
              clouds.push_back(l == 0 ? &frames[layer[m].begin] : &layer[m].cloud);
              member_poses.push_back(out.poses[layer[m].begin]);
            }
            Outcome& o = outcomes[k];
            // The submap is made of entries: the members, or at a continuous layer 0 the
            // parts of their sweeps (entry_member: each entry's member).
            std::vector<ulc::PointSpan<S>> entries;
            for (const Cloud* c : clouds) entries.emplace_back(*c);
            std::vector<std::size_t> entry_member(clouds.size());
            for (std::size_t m = 0; m < clouds.size(); ++m) entry_member[m] = m;
            std::vector<Isometry3d> entry_poses;
            if (clouds.size() >= 2) {
              o.ran = true;
              std::size_t knots = clouds.size();
              if (l == 0 && sweeps) {
                const SweepWindow<ulc::PointSpan<S>> sw =
                    hierarchy_detail::sweep_window(*sweeps, first, last, options.end_knot);
                std::vector<Isometry3d> knot_poses = member_poses;
                if (sw.deskew.size() > clouds.size()) knot_poses.push_back(out.poses[last]);
                knots = knot_poses.size();
                SweepBaResult sr = sweep_window_ba(sw, knot_poses, options.ba);
                o.ba = std::move(sr.ba);
                entries.clear();
                for (const ulc::PointSpan<S>* part : sw.clouds) entries.push_back(*part);
                entry_member = sw.sweep;
                entry_poses = std::move(sr.entry_poses);
              } else {
                o.ba = window_ba(clouds, member_poses, options.ba);
                entry_poses = o.ba.poses;
              }
              const bool usable = o.ba.ok() || o.ba.status == WindowBaStatus::not_converged;
              if (usable)
                o.information = hierarchy_detail::marginal_information(o.ba, options.min_sigma);
              if (usable && o.information.size() + 1 == knots) {
                if (knots > clouds.size() && options.end_knot_factor) {
                  HierarchyFactor f;  // to the next frame, where the last sweep ends
                  f.from = layer[first].begin;
                  f.to = last;
                  f.measured = o.ba.poses[0].inverse() * o.ba.poses.back();
                  f.information = o.information.back();
                  f.layer = 0;
                  o.end_factor.push_back(f);
                }
                o.information.resize(clouds.size() - 1);
                o.ba.poses.resize(clouds.size());
              } else {
                o.information.clear();
              }
            }
            if (o.information.empty()) {  // no usable BA: keep the start
              o.ba.poses = member_poses;
              entry_poses.clear();
              for (std::size_t e = 0; e < entries.size(); ++e)
                entry_poses.push_back(member_poses[entry_member[e]]);
            }
            // The submap: every entry's points in the first member's coordinates.
            const Isometry3d first_inv = o.ba.poses[0].inverse();
            Cloud merged;
            for (std::size_t e = 0; e < entries.size(); ++e) {
              const Isometry3d T = first_inv * entry_poses[e];
              for (const auto& p : entries[e])
                merged.push_back((T * p.template cast<double>()).template cast<S>());
            }
            o.submap.begin = layer[first].begin;
            o.submap.end = layer[last - 1].end;
            const auto down = ulc::voxel_downsample(merged, options.submap_voxel);
            o.submap.cloud = down.ok() ? down.cloud.points : merged;
          }
        });
    // Serial, in window order: move subtrees, collect factors, form the next layer.
    std::vector<HierarchyMember<S>> next;
    for (std::size_t k = 0; k < n_windows; ++k) {
      Outcome& o = outcomes[k];
      const std::size_t first = k * w, last = std::min(first + w, layer.size());
      if (o.ran) {
        ++out.windows;
        out.planes += o.ba.planes;
        if (o.information.empty()) ++out.failed_windows;
      }
      for (std::size_t m = first; m < last; ++m) {
        const Isometry3d old_pose = out.poses[layer[m].begin];
        const Isometry3d delta = o.ba.poses[m - first] * old_pose.inverse();
        for (std::size_t f = layer[m].begin; f < layer[m].end; ++f)
          out.poses[f] = delta * out.poses[f];
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
      next.push_back(std::move(o.submap));
    }
    out.members.push_back(std::move(layer));
    layer = std::move(next);
  }
  if (!layer.empty()) out.members.push_back(std::move(layer));
  return out;
}

}  // namespace hots
