// The first steps of hots::refine (refine_steps.hpp): the inputs checked, and each LiDAR's frames
// deskewed with its own odometry, thinned and, for the sweep bundle adjustment, ordered by part of
// their sweep.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "hots/hierarchy.hpp"
#include "hots/options.hpp"
#include "hots/refine_state.hpp"
#include "hots/refine_statistics.hpp"
#include "ulc/core/batched_for.hpp"
#include "ulc/core/deskew.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace hots {

namespace hots_detail {

/// Orders a frame's thinned points by part of its sweep (stably: `parts` equal parts of the
/// sweep's duration by each point's time, `times` seconds into the sweep) and returns the parts
/// as views into them, each with its points' mean fraction of the sweep. Without times the frame
/// is one part at fraction 0. The views are the parts without a second copy of the frame.
template <typename S>
SweepParts<S> order_by_part(std::vector<ulc::Vec3<S>>& points, const std::vector<double>* times,
                            const std::pair<Isometry3d, double>& motion, int parts) {
  const std::size_t n = times ? static_cast<std::size_t>(std::max(parts, 1)) : 1;
  std::vector<std::size_t> part(points.size(), 0), count(n, 0);
  std::vector<double> fraction_sum(n, 0.0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double f = times ? (*times)[i] / motion.second : 0.0;
    const int j = std::clamp(static_cast<int>(std::floor(f * static_cast<double>(n))), 0,
                             static_cast<int>(n) - 1);
    part[i] = static_cast<std::size_t>(j);
    ++count[part[i]];
    fraction_sum[part[i]] += f;
  }
  std::vector<std::size_t> start(n, 0);
  for (std::size_t j = 1; j < n; ++j) start[j] = start[j - 1] + count[j - 1];
  std::vector<ulc::Vec3<S>> ordered(points.size());
  std::vector<std::size_t> next = start;
  for (std::size_t i = 0; i < points.size(); ++i) ordered[next[part[i]]++] = points[i];
  points.swap(ordered);
  SweepParts<S> sp;
  sp.deskew = motion.first;
  for (std::size_t j = 0; j < n; ++j) {
    sp.parts.emplace_back(points.data() + start[j], count[j]);
    sp.fraction.push_back(count[j] ? fraction_sum[j] / static_cast<double>(count[j]) : 0.0);
  }
  return sp;
}

/// Deskewed and downsampled copies of every stride-th frame (the others stay empty);
/// sweep(k) gives frame k's motion over its sweep and the sweep's duration. With `sweeps`, each
/// frame's kept points are also ordered by part of the sweep and `sweeps` holds the parts
/// (order_by_part; a frame without point times is one part at fraction 0): views into the
/// returned frames, valid while those vectors are neither copied from nor reallocated.
/// progress (optional) gets the fraction of frames done, every few frames.
template <typename S, class Frames, class Sweep>
std::vector<std::vector<ulc::Vec3<S>>> prepare_frames(const Frames& frames, const Sweep& sweep,
                                                      double voxel, std::size_t stride = 1,
                                                      std::vector<SweepParts<S>>* sweeps = nullptr,
                                                      int parts = 1,
                                                      const ulc::StepProgress& progress = {}) {
  std::vector<std::vector<ulc::Vec3<S>>> out(frames.size());
  if (sweeps) sweeps->assign(frames.size(), SweepParts<S>{});
  stride = std::max<std::size_t>(stride, 1);
  ulc::parallel_for_in_batches(
      frames.size(), ulc::default_batch_size(),
      [&](std::size_t k) {
        if (k % stride != 0) return;
        const std::pair<Isometry3d, double> motion = sweep(k);
        const auto& frame = frames[k];  // once: a FrameSource reads it on each access
        auto deskewed = ulc::deskew(frame, motion.first, motion.second);
        const bool timed = sweeps && ulc::traits::has_time(frame) && motion.second > 0.0;
        if (timed) {
          deskewed.times.resize(deskewed.points.size());
          for (std::size_t i = 0; i < deskewed.points.size(); ++i)
            deskewed.times[i] = ulc::traits::time(frame, i);
        }
        const auto down = ulc::voxel_downsample(deskewed, voxel);
        const auto& cloud = down.ok() ? down.cloud : deskewed;
        out[k].reserve(cloud.points.size());
        for (const auto& p : cloud.points) out[k].push_back(p.template cast<S>());
        if (!sweeps) return;
        const bool split = timed && cloud.times.size() == out[k].size();
        (*sweeps)[k] = order_by_part(out[k], split ? &cloud.times : nullptr, motion, parts);
      },
      [&](std::size_t done) {
        if (progress) progress(static_cast<double>(done) / static_cast<double>(frames.size()));
      });
  return out;
}

/// Constant velocity from a LiDAR's own poses: the motion to the next frame.
inline std::pair<Isometry3d, double> own_sweep(const std::vector<double>& times,
                                               const std::vector<Isometry3d>& poses,
                                               std::size_t k) {
  const std::size_t j = k + 1 < times.size() ? k : k - 1;
  return {poses[j].inverse() * poses[j + 1], times[j + 1] - times[j]};
}

/// Every frame deskewed with its LiDAR's own poses (own_sweep).
template <typename S, class Frames>
std::vector<std::vector<ulc::Vec3<S>>> prepare_frames(
    const Frames& frames, const std::vector<double>& times, const std::vector<Isometry3d>& poses,
    double voxel, std::vector<SweepParts<S>>* sweeps = nullptr, int parts = 1,
    const ulc::StepProgress& progress = {}) {
  return prepare_frames<S>(
      frames, [&](std::size_t k) { return own_sweep(times, poses, k); }, voxel, 1, sweeps, parts,
      progress);
}

inline bool usable_times(const std::vector<double>& t) {
  if (t.size() < 2) return false;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i])) return false;
    if (i > 0 && !(t[i] > t[i - 1])) return false;
  }
  return true;
}

/// Why refine cannot run on these sequences; nullptr when it can.
template <class SeqA, class SeqB>
const char* input_problem(const SeqA& a, const SeqB& b, const Isometry3d& extrinsic,
                          const RefineOptions& options) {
  if (a.frames.size() != a.times.size() || a.frames.size() != a.poses.size() ||
      b.frames.size() != b.times.size() || b.frames.size() != b.poses.size())
    return "frame, time and pose counts differ";
  if (!usable_times(a.times) || !usable_times(b.times))
    return "need two or more strictly increasing times";
  if (!extrinsic.matrix().allFinite()) return "extrinsic not finite";
  for (const auto* list : {&a.poses, &b.poses})
    for (const Isometry3d& T : *list)
      if (!T.matrix().allFinite()) return "a pose is not finite";
  if (!(options.frame_voxel > 0.0) || options.passes < 1 || !(options.extrinsic_sigma_m > 0.0) ||
      !(options.extrinsic_sigma_rad > 0.0))
    return "bad options";
  return nullptr;
}

/// Both LiDARs' frames deskewed with their own odometry and thinned (statistics: prepare);
/// progress gets the fraction done, a's frames first.
template <typename S, class SeqA, class SeqB>
void prepare_lidars(const SeqA& seq_a, const SeqB& seq_b, RefineState<S>& s,
                    const RefineOptions& options, RefineStatistics& st,
                    const ulc::StepProgress& progress) {
  const int parts = options.hierarchy.sweep_parts;
  const double share_a = s.a.reused ? 0.0 : share_of_a(s.a.times.size(), s.b.times.size());
  for (const auto& T : s.b.odometry) s.b.world.push_back(s.mapa_mapb * T);
  if (!s.a.reused) {
    s.a.prepared->built_from = s.a.odometry;
    s.a.world = s.a.odometry;
    s.a.frames = prepare_frames<S>(seq_a.frames, s.a.times, s.a.odometry, options.frame_voxel,
                                   parts > 1 ? &s.a.sweeps : nullptr, parts,
                                   ulc::progress_within(progress, 0.0, share_a));
  }
  s.b.frames = prepare_frames<S>(seq_b.frames, s.b.times, s.b.odometry, options.frame_voxel,
                                 parts > 1 ? &s.b.sweeps : nullptr, parts,
                                 ulc::progress_within(progress, share_a, 1.0));
  st.prepare_seconds = lap(s.clock);
}

}  // namespace hots_detail
}  // namespace hots
