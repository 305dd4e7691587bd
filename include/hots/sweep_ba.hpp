// Window bundle adjustment with continuous-time sweeps: a LiDAR frame is not one rigid cloud
// but a sweep whose pose moves from its frame's pose to the next frame's (paper Sec. "Pose
// Refinement by Hierarchical Optimization"; the frames' poses are the trajectory's knots).
//
// Conventions this header owns:
//   - Variables: the poses T_world_k of V consecutive frames (the window's frames, and the
//     next frame's when there is one: the last sweep ends there). Variable 0 is the gauge.
//   - Entries: parts of the sweeps (points of one sweep grouped by time). Entry e belongs to
//     sweep k (a variable) and sits at fraction s_e of it (its points' mean time / the frame
//     period). Its points were deskewed with the motion M_k (ulc::deskew: the point at fraction
//     s moved by exp(s log M_k)), so the entry's pose is
//        E_e = T_k exp(s_e log(T_k^-1 T_k+1)) exp(-s_e log M_k),
//     the pose of the sweep at s_e under constant velocity between the two knots, with the
//     deskew undone. For the window's last variable (no next knot) E_e = T_k: the sweep stays as
//     deskewed. Treating a part's points at their mean time is exact to first order in the
//     correction of the sweep's motion times the part's duration.
//   - Cost: window_ba's plane cost over the entries (point_cluster.hpp). Its gradient and
//     Hessian with respect to the entries' left perturbations are mapped to the variables'
//     by the chain rule, zeta_e = J_e [xi_k; xi_k+1] (J_e by central differences of
//     log(E_e(xi) E_e^-1): the map is smooth and 12 evaluations per entry cost nothing beside
//     the planes), plane by plane on the factored forms (PlaneForms): a plane's cross terms are
//     one rank-3 update over its variables (hessian_factor), and its entries' own second-order
//     blocks are summed per entry over all planes and mapped through J_e once (the map is
//     linear: one 12 x 12 product per entry instead of one per plane and entry;
//     docs/experiments/sixty_second_drive_speed.md). The Hessian is J^T H J (the map's second
//     derivative is left out, as in Gauss-Newton: it only shapes the steps, and LM accepts a
//     step on the true cost).
//   - The result is a WindowBaResult over the V variables (hessian 6V x 6V, window frame) and
//     each entry's refined pose.
//   - Nothing here throws or prints; the same bits for any number of threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "hots/window_ba.hpp"
#include "ulc/core/lie.hpp"

namespace hots {

/// The sweeps of a window: entries (parts) and how each hangs on the variables.
template <class Cloud>
struct SweepWindow {
  std::vector<const Cloud*> clouds;  ///< entries
  std::vector<std::size_t> sweep;    ///< entry -> its sweep's variable k
  std::vector<double> fraction;      ///< entry -> s_e
  std::vector<Isometry3d> deskew;    ///< variable k -> M_k its points were deskewed with
};

struct SweepBaResult {
  WindowBaResult ba;                    ///< over the variables
  std::vector<Isometry3d> entry_poses;  ///< T_world_e, refined
};

namespace sweep_ba_detail {

/// E_e for every entry from the variables (see the header comment).
template <class Cloud>
std::vector<Isometry3d> entry_poses(const SweepWindow<Cloud>& w, const std::vector<Isometry3d>& x) {
  std::vector<Isometry3d> out(w.clouds.size());
  for (std::size_t e = 0; e < out.size(); ++e) {
    const std::size_t k = w.sweep[e];
    if (k + 1 >= x.size()) {
      out[e] = x[k];
      continue;
    }
    const double s = w.fraction[e];
    const Vec6d xi = ulc::se3_log(Isometry3d(x[k].inverse() * x[k + 1]));
    const Vec6d m = ulc::se3_log(w.deskew[k]);
    out[e] = x[k] * ulc::se3_exp(Vec6d(s * xi)) * ulc::se3_exp(Vec6d(-s * m));
  }
  return out;
}

/// d zeta_e / d [xi_k; xi_k+1] (6 x 12) by central differences; zero columns for a missing k+1.
template <class Cloud>
Eigen::Matrix<double, 6, 12> entry_jacobian(const SweepWindow<Cloud>& w,
                                            const std::vector<Isometry3d>& x, std::size_t e) {
  Eigen::Matrix<double, 6, 12> J = Eigen::Matrix<double, 6, 12>::Zero();
  const std::size_t k = w.sweep[e];
  if (k + 1 >= x.size()) {
    J.leftCols<6>().setIdentity();
    return J;
  }
  const double h = 1e-6;
  SweepWindow<Cloud> one;
  one.clouds = {w.clouds[e]};
  one.sweep = {0};
  one.fraction = {w.fraction[e]};
  one.deskew = {w.deskew[k]};
  const std::vector<Isometry3d> base = {x[k], x[k + 1]};
  const Isometry3d E_inv = entry_poses(one, base)[0].inverse();
  for (int c = 0; c < 12; ++c) {
    Vec6d d = Vec6d::Zero();
    d(c % 6) = h;
    std::vector<Isometry3d> plus = base, minus = base;
    plus[static_cast<std::size_t>(c / 6)] = ulc::se3_exp(d) * plus[static_cast<std::size_t>(c / 6)];
    minus[static_cast<std::size_t>(c / 6)] =
        ulc::se3_exp(Vec6d(-d)) * minus[static_cast<std::size_t>(c / 6)];
    const Vec6d zp = ulc::se3_log(Isometry3d(entry_poses(one, plus)[0] * E_inv));
    const Vec6d zm = ulc::se3_log(Isometry3d(entry_poses(one, minus)[0] * E_inv));
    J.col(c) = (zp - zm) / (2.0 * h);
  }
  return J;
}

/// Each entry's own second-order block, summed over its planes, through its Jacobian J
/// (6 x 12, [xi_k; xi_k+1]): J^T own J into the blocks of its variables. The map is linear, so
/// one product per entry replaces one per plane and entry.
template <class Cloud>
void add_entry_own(const SweepWindow<Cloud>& w, std::size_t V,
                   const std::vector<Eigen::Matrix<double, 6, 12>>& jacobians,
                   window_ba_detail::Sums& sums) {
  for (std::size_t e = 0; e < sums.entry_own.size(); ++e) {
    const std::size_t k = w.sweep[e];
    const std::size_t sides = k + 1 < V ? 2 : 1;
    const Eigen::Matrix<double, 12, 12> mapped =
        jacobians[e].transpose() * sums.entry_own[e] * jacobians[e];
    const auto at = static_cast<Eigen::Index>(6 * k);
    const auto n = static_cast<Eigen::Index>(6 * sides);
    sums.H.block(at, at, n, n) += mapped.topLeftCorner(n, n);
  }
}

/// Cost, gradient and Hessian over the variables: each plane's factored forms (PlaneForms) are
/// mapped through the entries' Jacobians and their outer products summed per variable pair;
/// the planes' own blocks per entry (add_entry_own).
template <class Cloud>
window_ba_detail::Sums evaluate(const std::vector<Plane>& planes, const SweepWindow<Cloud>& w,
                                const std::vector<Isometry3d>& x, const WindowBaOptions& o) {
  using Mat63 = Eigen::Matrix<double, 6, 3>;
  const std::vector<Isometry3d> entries = entry_poses(w, x);
  std::vector<Eigen::Matrix<double, 6, 12>> jacobians(entries.size());
  for (std::size_t e = 0; e < entries.size(); ++e) jacobians[e] = entry_jacobian(w, x, e);
  const std::size_t V = x.size();
  const auto add_plane = [&](const Plane& plane, const PlaneForms& f, window_ba_detail::Sums& acc) {
    std::vector<std::size_t> vars;  // the plane's variables, and their mapped forms
    std::vector<Mat63> W;
    std::vector<Vec6d> E;
    for (std::size_t a = 0; a < plane.frames.size(); ++a) {
      const std::size_t e = plane.frames[a].frame, k = w.sweep[e];
      acc.entry_own[e] += f.own[a];
      const std::size_t sides = k + 1 < V ? 2 : 1;
      for (std::size_t side = 0; side < sides; ++side) {
        const auto Ja = jacobians[e].template middleCols<6>(static_cast<Eigen::Index>(6 * side));
        const std::size_t var = k + side;
        const auto it = std::find(vars.begin(), vars.end(), var);
        const std::size_t slot = static_cast<std::size_t>(it - vars.begin());
        if (it == vars.end()) {
          vars.push_back(var);
          W.push_back(Mat63::Zero());
          E.push_back(Vec6d::Zero());
        }
        W[slot] += Ja.transpose() * f.w[a];
        E[slot] += Ja.transpose() * f.e[a];
      }
    }
    // The gradient from the mapped forms, then each variable's forms become its Hessian factor.
    for (std::size_t i = 0; i < vars.size(); ++i) {
      acc.g.template segment<6>(static_cast<Eigen::Index>(6 * vars[i])) += W[i].col(0);
      W[i] = hessian_factor(f, W[i], E[i]);
    }
    for (std::size_t i = 0; i < vars.size(); ++i)
      for (std::size_t j = i; j < vars.size(); ++j)
        subtract_cross_terms(acc.H, static_cast<Eigen::Index>(6 * vars[i]),
                             static_cast<Eigen::Index>(6 * vars[j]), W[i], W[j], j != i);
  };
  window_ba_detail::Sums out = window_ba_detail::sum_planes(planes, entries, V, o, add_plane, true);
  add_entry_own(w, V, jacobians, out);
  out.H = 0.5 * (out.H + out.H.transpose());
  return out;
}

}  // namespace sweep_ba_detail

/// Refines variables 1.. with variable 0 fixed (see the header comment). poses_world: the V
/// variables' starting poses.
template <class Cloud>
SweepBaResult sweep_window_ba(const SweepWindow<Cloud>& window,
                              const std::vector<Isometry3d>& poses_world,
                              const WindowBaOptions& options = {}) {
  namespace d = window_ba_detail;
  namespace sd = sweep_ba_detail;
  SweepBaResult out;
  WindowBaResult& result = out.ba;
  result.poses = poses_world;
  const std::size_t V = poses_world.size();
  const std::size_t E = window.clouds.size();
  bool consistent = V >= 2 && E >= 1 && window.sweep.size() == E && window.fraction.size() == E &&
                    window.deskew.size() == V && d::valid_options(options);
  for (std::size_t e = 0; consistent && e < E; ++e)
    consistent = window.sweep[e] < V && std::isfinite(window.fraction[e]);
  for (const Isometry3d& T : poses_world) consistent = consistent && T.matrix().allFinite();
  if (!consistent) {
    result.status = WindowBaStatus::invalid_input;
    result.reason = "sweep window: inconsistent entries, poses or options";
    return out;
  }
  const std::vector<Isometry3d> x = d::run_rounds(
      window.clouds, poses_world,
      [&](const std::vector<Isometry3d>& at) { return sd::entry_poses(window, at); },
      [&](const std::vector<Plane>& planes, const std::vector<Isometry3d>& at) {
        return sd::evaluate(planes, window, at, options);
      },
      options, result);
  for (const Isometry3d& P : sd::entry_poses(window, x))
    out.entry_poses.push_back(poses_world[0] * P);
  return out;
}

}  // namespace hots
