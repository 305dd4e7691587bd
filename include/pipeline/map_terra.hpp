// TERRA on local maps: the paper's remedy for LiDARs whose single frames barely overlap (a
// narrow-FoV Livox Tele-15 frame fills ~48 cells of the N = 10000 lattice). Each LiDAR gets its
// own local map from its own single-LiDAR odometry over a short window of frames while the
// vehicle drives, and TERRA compares the two maps instead of two frames.
//
// Conventions this header owns:
//   - Window: frames first, first + 1, ... of each LiDAR whose timestamps lie within
//     MapTerraOptions::window_s of that LiDAR's frame `first` (at most max_frames). Frames
//     before `first` are never touched.
//   - Map frame: the LiDAR's own frame at the window's last frame (MapTerraOptions::anchor; the
//     first frame, `first`, on request). Both windows span the same seconds from frames taken
//     at about the same instant (the same index, as the frame search assumes too), so both
//     anchors were too and the rotation between the two maps' frames is R_base_target: the
//     search result means what a frame search's does.
//   - Each frame is deskewed to its timestamp with its odometry step's twist
//     (odometry::prepare_scan with `scan`), placed with its pose at that timestamp, and the stack
//     is thinned by voxel centroids; the voxel doubles until the map holds at most max_points
//     (a bounded descriptor cost, whatever the window).
//   - An odometry that could not register some frames (registration_failed) still gives a
//     map (its poses are predictions there; the statistics count the failures); one that gives
//     no poses ends the call with the search status invalid_input and the reason.
//   - The motion frame (motion_frame.hpp, MapTerraOptions::motion): each map's travel over the
//     window (first to last frame, in the anchor frame) and largest planes give a rotation of
//     their own, reported beside the search's; the TERRA stage (terra_stage.hpp) decides.
//     The ground vote (window_vote.hpp) goes ahead of them when it is sure: a few target
//     frames of the window, each against the base's map moved into the base frame nearest it
//     in time (LocalMap::poses).
//   - Deterministic for any thread count (odometry, voxel thinning and search all are).
//   - Nothing here throws, exits or prints; it compiles with -fno-exceptions.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "odometry/frame_pairing.hpp"
#include "odometry/run_odometry.hpp"
#include "odometry/scan_preparation.hpp"
#include "pipeline/map_terra_options.hpp"
#include "pipeline/motion_frame.hpp"
#include "pipeline/window_vote.hpp"
#include "terra/ground_vote.hpp"
#include "terra/lattice.hpp"
#include "terra/ring_gap.hpp"
#include "terra/search.hpp"
#include "ulc/core/nearest_time.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace ulc {

template <typename S>
struct LocalMap {
  std::vector<Vec3<S>> points;    ///< in the LiDAR's frame at the anchor frame
  Vec3d travel = Vec3d::Zero();   ///< the window's first to last position, in the anchor frame
  std::vector<Isometry3d> poses;  ///< each window frame's pose in the anchor frame
  LocalMapStats stats;
  bool ok = false;  ///< the odometry gave poses (else points is empty and stats say why)
};

struct MapTerraResult {
  terra::SearchResult search;  ///< R_base_target between the maps' frames
  MotionReport motion;         ///< the maps' ground and travel (motion_frame.hpp), when enabled
  LocalMapStats base, target;
  double seconds = 0.0;  ///< maps and search
  bool ok() const { return search.ok(); }
};

namespace map_terra_detail {

/// Frames [first, first + count) of a container, as the odometry reads frames.
template <class Frames>
class FrameWindow {
 public:
  FrameWindow(const Frames& frames, std::size_t first, std::size_t count)
      : frames_(&frames), first_(first), count_(count) {}
  std::size_t size() const { return count_; }
  decltype(auto) operator[](std::size_t i) const { return (*frames_)[first_ + i]; }

 private:
  const Frames* frames_;
  std::size_t first_, count_;
};

/// How many frames from `first` lie in the window (at least one when first is valid).
inline std::size_t window_frames(const std::vector<double>& times, std::size_t first,
                                 const MapTerraOptions& o) {
  if (first >= times.size()) return 0;
  std::size_t n = 1;
  while (first + n < times.size() && n < o.max_frames &&
         times[first + n] - times[first] <= o.window_s + 1e-9)
    ++n;
  return n;
}

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace map_terra_detail

/// The local map of one LiDAR over its window from frame `first` (see the conventions above).
template <class Frames>
auto build_local_map(const Frames& frames, const std::vector<double>& times, std::size_t first,
                     const MapTerraOptions& options = {}) {
  using S = traits::scalar_t<odometry::detail::frame_cloud_t<Frames>>;
  using namespace map_terra_detail;
  const auto t0 = std::chrono::steady_clock::now();
  LocalMap<S> map;
  const std::size_t n = frames.size() == times.size() ? window_frames(times, first, options) : 0;
  map.stats.frames = n;
  if (n == 0) {
    map.stats.odometry_status = odometry::OdometryStatus::invalid_input;
    map.stats.odometry_reason =
        "no frame in the window (frame index past the end, or frame "
        "and timestamp counts differ)";
    return map;
  }
  const FrameWindow<Frames> window(frames, first, n);
  const std::vector<double> t(times.begin() + static_cast<std::ptrdiff_t>(first),
                              times.begin() + static_cast<std::ptrdiff_t>(first + n));
  const odometry::OdometryResult odo = odometry::run_single_odometry(window, t, options.odometry);
  map.stats.odometry_status = odo.status;
  map.stats.odometry_reason = odo.reason;
  map.stats.odometry_failed_steps = odo.failed_steps;
  if (!(odo.ok() || odo.status == odometry::OdometryStatus::registration_failed) ||
      odo.steps.size() != n) {
    map.stats.seconds = seconds_since(t0);
    return map;
  }
  // Stack the deskewed frames at their poses (steps are the frames, in order).
  const double period = odometry::frame_period(t);
  PointCloud<S> stack;
  for (std::size_t k = 0; k < n; ++k) {
    const odometry::OdometryStep& step = odo.steps[k];
    const auto scan = odometry::prepare_scan<S>(window[k], step.twist, period, options.scan);
    for (const auto& p : scan.dense)
      stack.points.push_back((step.pose_a * p.template cast<double>()).template cast<S>());
  }
  const Isometry3d& first_pose = odo.steps.front().pose_a;
  const Isometry3d& last_pose = odo.steps.back().pose_a;
  const Isometry3d& anchor = options.anchor == MapAnchor::last_frame ? last_pose : first_pose;
  map.travel = anchor.linear().transpose() * (last_pose.translation() - first_pose.translation());
  const Isometry3d from_anchor = anchor.inverse();
  if (options.anchor == MapAnchor::last_frame)
    for (auto& p : stack.points) p = (from_anchor * p.template cast<double>()).template cast<S>();
  for (const odometry::OdometryStep& step : odo.steps)
    map.poses.push_back(from_anchor * step.pose_a);
  map.stats.stacked_points = stack.points.size();
  // Thin: the voxel doubles until the map fits (a handful of passes at most).
  double voxel = options.voxel > 0.0 ? options.voxel : 0.2;
  PointCloud<S> thin = voxel_downsample(stack, voxel).cloud;
  while (thin.points.size() > options.max_points && voxel < 1e3) {
    voxel *= 2.0;
    thin = voxel_downsample(stack, voxel).cloud;
  }
  map.points = std::move(thin.points);
  map.stats.points = map.points.size();
  map.stats.voxel_used = voxel;
  map.stats.seconds = seconds_since(t0);
  map.ok = true;
  return map;
}

namespace map_terra_detail {

/// The base map's points in the frame of its window frame `k` (poses are in the anchor frame).
template <typename S>
std::vector<Vec3<S>> map_at_frame(const LocalMap<S>& map, std::size_t k) {
  const Isometry3d to_frame = map.poses[k].inverse();
  std::vector<Vec3<S>> out;
  out.reserve(map.points.size());
  for (const auto& p : map.points)
    out.push_back((to_frame * p.template cast<double>()).template cast<S>());
  return out;
}

}  // namespace map_terra_detail

/// The window's vote `v` (the tally's answer) into the motion report: a confident one is the
/// maps' rotation, ahead of the ground and travel's.
inline void report_vote(const terra::GroundVoteResult& v, const VoteTally& tally, std::size_t frame,
                        std::size_t frames, MotionReport& m) {
  m.vote = v;
  m.vote_ran = true;
  m.vote_frame = frame;
  m.votes = frames;
  m.votes_confident = tally.confident;
  m.votes_agreeing = tally.agreeing;
  if (!tally.ok) {
    if (!m.ok) m.reason += "; ground vote: " + tally.reason;
    return;
  }
  m.ok = true;
  m.reason.clear();
  m.rotation = m.vote.rotation;
  m.method = "ground vote";
}

/// The window's unsure pooled vote as the maps' rotation where the ground and travel was
/// refused (MotionFrameOptions::unsure_vote): when at least `min_score` of its votes landed.
/// A window whose sure answers conflict (answer.pooled false) stands in nothing.
inline void stand_in_unsure_vote(const WindowAnswer& answer, double min_score, MotionReport& m) {
  if (m.ok || answer.tally.ok || !answer.pooled || !(answer.vote.score >= min_score)) return;
  m.ok = true;
  m.reason.clear();
  m.rotation = answer.vote.rotation;
  m.method = "unsure ground vote";
}

namespace map_terra_detail {

/// What the ground vote reads of a map window: the base's map and both LiDARs' frames from
/// window frame `first` on.
template <typename SA, class FramesA, class FramesB>
struct VoteWindow {
  const LocalMap<SA>& base_map;
  const FramesA& frames_a;
  const std::vector<double>& times_a;
  const FramesB& frames_b;
  const std::vector<double>& times_b;
  std::size_t first = 0;
};

/// Some window frames' votes and what each voted on, in frame order.
struct FrameVotes {
  std::vector<std::size_t> frames;
  std::vector<terra::GroundVoteInput> inputs;
  std::vector<terra::GroundVoteResult> votes;
};

/// The votes of window frames `indices` (ascending), each against the base's map at the base
/// frame nearest it in time; a frame `before` already voted keeps its vote.
template <class Window>
FrameVotes vote_frames(const Window& w, const std::vector<std::size_t>& indices, bool free_space,
                       const terra::GroundVoteOptions& o, FrameVotes before = {}) {
  FrameVotes out;
  for (const std::size_t k : indices) {
    const auto it = std::find(before.frames.begin(), before.frames.end(), k);
    out.frames.push_back(k);
    if (it != before.frames.end()) {
      const auto i = static_cast<std::size_t>(it - before.frames.begin());
      out.inputs.push_back(std::move(before.inputs[i]));
      out.votes.push_back(std::move(before.votes[i]));
      continue;
    }
    const std::size_t j =
        nearest_time(w.times_a, w.times_b[w.first + k], w.first, w.base_map.poses.size());
    out.inputs.push_back(
        terra::prepare_ground_vote(map_at_frame(w.base_map, j), w.frames_b[w.first + k], o));
    out.votes.push_back(terra::ground_vote(out.inputs.back(), o));
    if (free_space) terra::add_free_space(out.inputs.back(), w.frames_a[w.first + j], o);
  }
  return out;
}

/// The window's answer from its frames' votes: their tally, with their pool beside it when
/// pool_votes (window_vote.hpp).
inline WindowAnswer answer_votes(const FrameVotes& fv, const MotionFrameOptions& o,
                                 const terra::GroundVoteOptions& vote_options) {
  const VoteTally tally = tally_votes(fv.votes, o.vote_agree_deg, o.vote.margin_separation_deg);
  if (!o.pool_votes) return {fv.votes[tally.chosen], tally, false};
  const PooledVote pool = pool_votes(fv.inputs, fv.votes, vote_options);
  return window_answer(fv.votes, tally, pool, o.vote.margin_separation_deg);
}

}  // namespace map_terra_detail

/// The ground vote of a few target window frames against the base's map (window_vote.hpp),
/// pooled (MotionFrameOptions::pool_votes) or tallied, into the motion report; more frames
/// vote where none of the first was sure (MotionFrameOptions::unsure_vote_frames).
template <typename SA, class FramesA, class FramesB>
void add_ground_vote(const LocalMap<SA>& base_map, const FramesA& frames_a,
                     const std::vector<double>& times_a, const FramesB& frames_b,
                     const std::vector<double>& times_b, std::size_t first,
                     std::size_t target_frames, std::size_t anchor, const MotionFrameOptions& o,
                     double base_ring_gap_deg, MotionReport& m) {
  using namespace map_terra_detail;
  terra::GroundVoteOptions vote_options = o.vote;
  if (o.fill_base_rings) vote_options.base_ring_gap_deg = base_ring_gap_deg;
  const VoteWindow<SA, FramesA, FramesB> window{base_map, frames_a, times_a,
                                                frames_b, times_b,  first};
  FrameVotes fv = vote_frames(window, vote_frame_indices(target_frames, o.vote_frames, anchor),
                              o.pool_votes, vote_options);
  if (fv.frames.empty()) return;  // an empty window: nothing to vote on
  WindowAnswer answer = answer_votes(fv, o, vote_options);
  if (answer.tally.confident == 0 && o.unsure_vote_frames > fv.frames.size()) {
    const auto more = vote_frame_indices(target_frames, o.unsure_vote_frames, anchor);
    fv = vote_frames(window, more, o.pool_votes, vote_options, std::move(fv));
    answer = answer_votes(fv, o, vote_options);
  }
  report_vote(answer.vote, answer.tally, fv.frames[answer.tally.chosen], fv.frames.size(), m);
  m.vote_pooled = answer.pooled;
  if (o.unsure_vote) stand_in_unsure_vote(answer, vote_options.min_score, m);
}

/// Both LiDARs' local maps over their windows and the motion frame they give, before any search.
template <typename SA, typename SB>
struct LocalMaps {
  LocalMap<SA> a;
  LocalMap<SB> b;
  MotionReport motion;  ///< not ok (with the reason) when a map failed or motion is disabled
  double seconds = 0.0;
  bool ok() const { return a.ok && b.ok; }
};

/// The local maps of both LiDARs from frame `first` of each, and their motion frame.
/// progress (optional) gets the share done: 0.5 after the base's map, 1 at the end.
template <class FramesA, class FramesB>
auto build_local_maps(const FramesA& frames_a, const std::vector<double>& times_a,
                      const FramesB& frames_b, const std::vector<double>& times_b,
                      std::size_t first, const MapTerraOptions& options = {},
                      const std::function<void(double)>& progress = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  auto a = build_local_map(frames_a, times_a, first, options);
  if (progress) progress(0.5);
  auto b = build_local_map(frames_b, times_b, first, options);
  LocalMaps<typename decltype(a.points)::value_type::Scalar,
            typename decltype(b.points)::value_type::Scalar>
      maps{std::move(a), std::move(b), {}, 0.0};
  if (!maps.ok()) {
    maps.motion.reason = "a local map could not be built";
  } else if (options.motion.enabled) {
    maps.motion =
        motion_rotation(motion_view(maps.a.points, maps.a.travel, options.motion),
                        motion_view(maps.b.points, maps.b.travel, options.motion), options.motion);
    if (maps.motion.ok) maps.motion.method = "ground and travel";
    if (options.motion.ground_vote) {
      const std::size_t n = maps.b.stats.frames;
      const std::size_t anchor = options.anchor == MapAnchor::last_frame ? n - 1 : 0;
      add_ground_vote(maps.a, frames_a, times_a, frames_b, times_b, first, n, anchor,
                      options.motion, terra::ring_gap_deg(frames_a[first]), maps.motion);
    }
  } else {
    maps.motion.reason = "the motion frame is disabled (MapTerraOptions::motion)";
  }
  maps.seconds = map_terra_detail::seconds_since(t0);
  if (progress) progress(1.0);
  return maps;
}

/// TERRA's search on built local maps (d1 = MapTerraOptions::d1 when set). `lattice` must have
/// params.lattice_size points.
template <typename SA, typename SB>
MapTerraResult search_local_maps(const terra::Lattice& lattice, const LocalMaps<SA, SB>& maps,
                                 const terra::SearchParams& params = {},
                                 const MapTerraOptions& options = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  MapTerraResult r;
  r.base = maps.a.stats;
  r.target = maps.b.stats;
  r.motion = maps.motion;
  if (!maps.ok()) {
    const LocalMapStats& bad = maps.a.ok ? r.target : r.base;
    r.search.status = terra::SearchStatus::invalid_input;
    r.search.reason = std::string(maps.a.ok ? "target" : "base") + " local map: odometry " +
                      odometry::to_string(bad.odometry_status) + ": " + bad.odometry_reason;
  } else {
    terra::SearchParams p = params;
    p.progress = {};
    if (options.d1 > 0.0) {
      p.distance.d1 = options.d1;
      p.adaptive_d1.enabled = false;
    }
    r.search = terra::estimate_rotation(lattice, maps.a.points, maps.b.points, p);
  }
  r.seconds = maps.seconds + map_terra_detail::seconds_since(t0);
  return r;
}

/// TERRA on the two LiDARs' local maps from frame `first` of each (see the conventions above):
/// build_local_maps, then search_local_maps. `lattice` must have params.lattice_size points
/// (reuse one across calls when you can).
template <class FramesA, class FramesB>
MapTerraResult map_terra(const terra::Lattice& lattice, const FramesA& frames_a,
                         const std::vector<double>& times_a, const FramesB& frames_b,
                         const std::vector<double>& times_b, std::size_t first,
                         const terra::SearchParams& params = {},
                         const MapTerraOptions& options = {},
                         const std::function<void(double)>& progress = {}) {
  std::function<void(double)> building;
  if (progress) building = [&progress](double f) { progress(0.8 * f); };
  if (progress) progress(0.0);
  const auto maps =
      build_local_maps(frames_a, times_a, frames_b, times_b, first, options, building);
  MapTerraResult r = search_local_maps(lattice, maps, params, options);
  if (progress) progress(1.0);
  return r;
}

/// Same, building the lattice of params.lattice_size points first.
template <class FramesA, class FramesB>
MapTerraResult map_terra(const FramesA& frames_a, const std::vector<double>& times_a,
                         const FramesB& frames_b, const std::vector<double>& times_b,
                         std::size_t first, const terra::SearchParams& params = {},
                         const MapTerraOptions& options = {},
                         const std::function<void(double)>& progress = {}) {
  if (params.lattice_size < 2) {
    MapTerraResult r;
    r.search.reason = "lattice_size must be at least 2";
    return r;
  }
  return map_terra(terra::Lattice(params.lattice_size), frames_a, times_a, frames_b, times_b, first,
                   params, options, progress);
}

}  // namespace ulc
