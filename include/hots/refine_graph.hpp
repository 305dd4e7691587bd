// hots::refine's pose graph (refine_steps.hpp): a variable per frame and one for the extrinsic C;
// the bundle adjustment's factors, the cross links, the boundaries, and the ties of C to both
// LiDARs' poses at a clock offset.
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

#include "hots/options.hpp"
#include "hots/pose_graph.hpp"
#include "hots/refine_state.hpp"
#include "hots/refine_statistics.hpp"

namespace hots {

namespace hots_detail {

/// Factor kinds of the graph (PoseFactor::kind), for its statistics.
enum FactorKind : int { ba_factor = 0, link_factor = 1, tie_factor = 2, boundary_factor = 3 };

inline void add_relative(PoseGraph& graph, std::size_t from, std::size_t to, const Isometry3d& Z,
                         const Mat6d& information, double huber, FactorKind kind) {
  PoseFactor f;
  f.from = from;
  f.to = to;
  f.measured = Z;
  f.sqrt_information = sqrt_information(information);
  f.huber = huber;
  f.kind = kind;
  graph.add_factor(f);
}

/// A factor across each boundary between two top-layer submaps that no window spans: the
/// bridge's BA factors when it has one (already in), else the registered boundary, else the
/// odometry's step across it (when boundary_sigma_* are set).
template <typename S>
void add_boundaries(PoseGraph& graph, const RefineLidar<S>& l, const RefineOptions& options,
                    RefineStatistics& st) {
  if (l.hierarchy.members.empty()) return;
  const bool odometry_boundaries =
      options.boundary_sigma_m > 0.0 && options.boundary_sigma_rad > 0.0;
  const auto& top = l.hierarchy.members.back();
  for (std::size_t m = 0; m + 1 < top.size(); ++m) {
    if (m < l.bridges.bridged.size() && l.bridges.bridged[m]) {
      ++st.boundary_bridges;
      continue;
    }
    if (m < l.boundaries.size() && l.boundaries[m]) {
      const CrossLink& b = *l.boundaries[m];
      add_relative(graph, l.first_var + b.frame_a, l.first_var + b.frame_b, b.measured,
                   b.information, options.link_huber, boundary_factor);
      ++st.boundary_links;
    } else if (odometry_boundaries) {
      const std::size_t from = top[m].end - 1, to = top[m + 1].begin;
      const Mat6d sqrt_info =
          isotropic_sqrt_information(options.boundary_sigma_m, options.boundary_sigma_rad);
      add_relative(graph, l.first_var + from, l.first_var + to,
                   l.odometry[from].inverse() * l.odometry[to],
                   Mat6d(sqrt_info.transpose() * sqrt_info), 0.0, boundary_factor);
    } else {
      continue;
    }
    ++st.boundary_factors;
  }
}

/// The pose graph: a variable per frame (a's first is the gauge) and one for C; the windows'
/// and bridges' BA factors, the cross links and the boundaries. The ties come later (set_ties).
template <typename S>
void build_graph(RefineState<S>& s, const Isometry3d& extrinsic, const RefineOptions& options,
                 RefineStatistics& st) {
  PoseGraph& graph = s.graph;
  s.b.first_var = s.a.world.size();
  for (std::size_t i = 0; i < s.a.world.size(); ++i) graph.add_variable(s.a.world[i], i == 0);
  for (const Isometry3d& T : s.b.world) graph.add_variable(T);
  s.extrinsic_var = graph.add_variable(extrinsic);
  for (const RefineLidar<S>* l : {&s.a, &s.b}) {
    for (const auto& f : l->hierarchy.factors)
      add_relative(graph, l->first_var + f.from, l->first_var + f.to, f.measured, f.information,
                   0.0, ba_factor);
  }
  for (const RefineLidar<S>* l : {&s.a, &s.b}) {
    for (const auto& f : l->bridges.factors)
      add_relative(graph, l->first_var + f.from, l->first_var + f.to, f.measured, f.information,
                   options.bridge_huber, ba_factor);
  }
  st.ba_factors = s.a.hierarchy.factors.size() + s.b.hierarchy.factors.size() +
                  s.a.bridges.factors.size() + s.b.bridges.factors.size();
  for (const auto& l : s.links)
    add_relative(graph, l.frame_a, s.b.first_var + l.frame_b, l.measured, l.information,
                 options.link_huber, link_factor);
  add_boundaries(graph, s.a, options, st);
  add_boundaries(graph, s.b, options, st);
  s.first_tie = graph.factors.size();
}

/// The a frame nearest to t (a's clock) and a's motion from it to t (interpolated or
/// extrapolated with the neighbouring frame).
inline std::pair<std::size_t, Isometry3d> a_at(const std::vector<double>& times,
                                               const std::vector<Isometry3d>& poses, double t) {
  auto it = std::lower_bound(times.begin(), times.end(), t);
  std::size_t k = static_cast<std::size_t>(it - times.begin());
  if (k == times.size() || (k > 0 && t - times[k - 1] <= times[k] - t)) --k;
  const std::size_t j = t >= times[k] ? std::min(k, times.size() - 2) : (k > 0 ? k - 1 : 0);
  const double span = times[j + 1] - times[j];
  const double alpha = span > 0.0 ? (t - times[j]) / span : 0.0;
  const Isometry3d at_t = ulc::interpolate(poses[j], poses[j + 1], alpha);
  return {k, poses[k].inverse() * at_t};
}

/// The extrinsic ties at clock offset `offset`, replacing the previous ones: for every b frame
/// whose instant falls inside a's span, r = log((T_a L)^-1 T_b C^-1), with L a's motion from
/// its nearest frame to that instant on the current poses.
template <typename S>
void set_ties(RefineState<S>& s, double offset, const RefineOptions& options,
              RefineStatistics& st) {
  PoseGraph& graph = s.graph;
  graph.factors.resize(s.first_tie);
  const Mat6d tie_sqrt =
      isotropic_sqrt_information(options.extrinsic_sigma_m, options.extrinsic_sigma_rad);
  const std::vector<double>& ta = s.a.times;
  const std::vector<Isometry3d> pa(
      graph.variables.begin(), graph.variables.begin() + static_cast<std::ptrdiff_t>(ta.size()));
  for (std::size_t j = 0; j < s.b.times.size(); ++j) {
    const double t = s.b.times[j] + offset;  // a's clock
    if (t < ta.front() || t > ta.back()) continue;
    const auto [i, L] = a_at(ta, pa, t);
    PoseFactor f;
    f.from = i;
    f.from_offset = L;
    f.to = s.b.first_var + j;
    f.measured_var = s.extrinsic_var;
    f.sqrt_information = tie_sqrt;
    f.kind = tie_factor;
    graph.add_factor(f);
  }
  st.extrinsic_ties = graph.factors.size() - s.first_tie;
}

/// The graph's poses of one LiDAR.
template <typename S>
std::vector<Isometry3d> graph_poses(const RefineState<S>& s, const RefineLidar<S>& l) {
  const auto first = s.graph.variables.begin() + static_cast<std::ptrdiff_t>(l.first_var);
  return std::vector<Isometry3d>(first, first + static_cast<std::ptrdiff_t>(l.world.size()));
}

}  // namespace hots_detail
}  // namespace hots
