// Window bundle adjustment: the poses of a few frames refined so that the planes they see
// (plane_extraction.hpp) are as thin as possible (the paper's local LiDAR BA inside a window,
// Sec. "Pose Refinement by Hierarchical Optimization", after BALM).
//
// Conventions this header owns:
//   - Input poses T_world_frame of the window's frames. The BA works in the window frame, the
//     first frame's: T_window_i = T_world_0^-1 T_world_i. The first pose is the gauge and never
//     moves; the result's poses are T_world_0 * T_window_i (the first one is returned as given).
//   - Cost = sum over planes of lambda_min of the plane's scatter (point_cluster.hpp): the sum of
//     squared point-to-plane distances, m^2. Planes are extracted at the initial poses, and again
//     at the refined poses for each further round (options.rounds).
//   - Levenberg-Marquardt on the exact Hessian of that cost with left perturbations
//     T_window_i <- exp(xi_i) T_window_i, xi = [rho; phi]; damping H + mu I with Nielsen's rule
//     (mu *= max(1/3, 1 - (2 rho - 1)^3) on success, mu *= nu, nu *= 2 on failure).
//   - `hessian` (6W x 6W, frame 0's block included) and `gradient` are at the returned poses,
//     for perturbations in the window frame: the information of the relative poses
//     T_window_i is hessian / (2 noise_variance) (cost = sum of squared residuals), with
//     noise_variance = cost / (points - 3 planes).
//   - Sums over planes use deterministic_reduce with a fixed grain: the same bits for any
//     number of threads. Nothing here throws or prints.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "hots/options.hpp"
#include "hots/plane_extraction.hpp"
#include "hots/point_cluster.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/parallel_reduce.hpp"

namespace hots {

enum class WindowBaStatus { ok, not_converged, too_few_planes, invalid_input };

inline const char* to_string(WindowBaStatus s) {
  switch (s) {
    case WindowBaStatus::ok:
      return "ok";
    case WindowBaStatus::not_converged:
      return "not_converged";
    case WindowBaStatus::too_few_planes:
      return "too_few_planes";
    default:
      return "invalid_input";
  }
}

struct WindowBaResult {
  WindowBaStatus status = WindowBaStatus::ok;
  const char* reason = "";
  std::vector<Isometry3d> poses;  ///< T_world_i, refined
  Eigen::MatrixXd hessian;        ///< 6W x 6W, window frame (see the header comment)
  Eigen::VectorXd gradient;
  double initial_cost = 0.0;
  double cost = 0.0;
  double noise_variance = 0.0;  ///< m^2 per point
  std::size_t planes = 0;
  std::size_t points = 0;
  std::size_t degenerate_planes = 0;  ///< at the returned poses
  int iterations = 0;                 ///< LM steps tried

  bool ok() const { return status == WindowBaStatus::ok; }
};

namespace window_ba_detail {

struct Sums {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  double cost = 0.0;
  std::size_t degenerate = 0;
  /// Per entry, its planes' own second-order blocks (PlaneForms::own) summed, for a caller
  /// that maps them through the entry's Jacobian once (sweep_ba.hpp); empty otherwise.
  std::vector<Mat6d> entry_own;
};

/// Sums over the planes in fixed chunks (the same bits for any number of threads): each
/// plane's factored derivatives (PlaneForms) at the entries' poses, its cost and degeneracy
/// counted here; add_plane(plane, forms, acc) adds its gradient and Hessian to acc (over
/// `variables` poses; with entry_own, Sums::entry_own has one block per entry).
template <class AddPlane>
Sums sum_planes(const std::vector<Plane>& planes, const std::vector<Isometry3d>& entry_poses,
                std::size_t variables, const WindowBaOptions& o, const AddPlane& add_plane,
                bool entry_own = false) {
  const auto n = static_cast<Eigen::Index>(6 * variables);
  Sums identity;
  identity.H = Eigen::MatrixXd::Zero(n, n);
  identity.g = Eigen::VectorXd::Zero(n);
  if (entry_own) identity.entry_own.assign(entry_poses.size(), Mat6d::Zero());
  const auto body = [&](std::size_t begin, std::size_t end, Sums acc) {
    for (std::size_t p = begin; p < end; ++p) {
      const PlaneForms f =
          plane_forms(planes[p].frames, entry_poses, planes[p].anchor, o.evaluation);
      acc.cost += f.cost;
      if (f.degenerate)
        ++acc.degenerate;
      else
        add_plane(planes[p], f, acc);
    }
    return acc;
  };
  const auto join = [](Sums a, const Sums& b) {
    a.H += b.H;
    a.g += b.g;
    for (std::size_t e = 0; e < a.entry_own.size(); ++e) a.entry_own[e] += b.entry_own[e];
    a.cost += b.cost;
    a.degenerate += b.degenerate;
    return a;
  };
  return ulc::deterministic_reduce(planes.size(), identity, body, join, o.grain);
}

inline Sums evaluate(const std::vector<Plane>& planes, const std::vector<Isometry3d>& poses,
                     const WindowBaOptions& o) {
  return sum_planes(planes, poses, poses.size(), o,
                    [](const Plane& plane, const PlaneForms& f, Sums& acc) {
                      const std::size_t K = plane.frames.size();
                      std::vector<Eigen::Matrix<double, 6, 3>> Z(K);
                      for (std::size_t a = 0; a < K; ++a) Z[a] = hessian_factor(f, f.w[a], f.e[a]);
                      for (std::size_t a = 0; a < K; ++a) {
                        const auto ia = static_cast<Eigen::Index>(6 * plane.frames[a].frame);
                        acc.g.segment<6>(ia) += f.w[a].col(0);
                        acc.H.block<6, 6>(ia, ia) += f.own[a];
                        for (std::size_t b = a; b < K; ++b) {
                          const auto ib = static_cast<Eigen::Index>(6 * plane.frames[b].frame);
                          subtract_cross_terms(acc.H, ia, ib, Z[a], Z[b], b != a);
                        }
                      }
                    });
}

inline double cost(const std::vector<Plane>& planes, const std::vector<Isometry3d>& poses,
                   const WindowBaOptions& o) {
  return ulc::deterministic_reduce(
      planes.size(), 0.0,
      [&](std::size_t begin, std::size_t end, double acc) {
        for (std::size_t p = begin; p < end; ++p)
          acc += plane_cost(planes[p].frames, poses, planes[p].anchor);
        return acc;
      },
      [](double a, double b) { return a + b; }, o.grain);
}

inline bool valid_options(const WindowBaOptions& o) {
  return valid_plane_extraction_options(o.planes) && o.rounds >= 1 && o.max_iterations >= 0 &&
         o.initial_damping > 0.0 && o.step_tolerance >= 0.0 && o.cost_tolerance >= 0.0 &&
         o.grain >= 1;
}

/// Levenberg-Marquardt over the poses x[1..] (x[0] is the gauge) on the planes extracted by
/// the caller: evaluate(x) gives the Sums, cost(x) the cost alone. Nielsen's damping rule (see
/// the header comment). Returns whether a stopping test was met; `sums` holds the last
/// accepted evaluation, `iterations` counts the steps tried.
template <class Evaluate, class Cost>
bool levenberg_marquardt(std::vector<Isometry3d>& x, Sums& sums, const Evaluate& evaluate,
                         const Cost& cost, const WindowBaOptions& o, int& iterations) {
  const auto m = static_cast<Eigen::Index>(6 * (x.size() - 1));
  double mu = o.initial_damping * std::max(sums.H.diagonal().tail(m).maxCoeff(), 1e-12);
  double nu = 2.0;
  for (int it = 0; it < o.max_iterations; ++it) {
    ++iterations;
    const Eigen::MatrixXd H = sums.H.bottomRightCorner(m, m);
    const Eigen::VectorXd g = sums.g.tail(m);
    const Eigen::LLT<Eigen::MatrixXd> llt(H + mu * Eigen::MatrixXd::Identity(m, m));
    if (llt.info() != Eigen::Success) {  // H indefinite here: damp harder
      mu *= nu;
      nu *= 2.0;
      continue;
    }
    const Eigen::VectorXd step = llt.solve(-g);
    if (!step.allFinite()) return false;
    if (step.cwiseAbs().maxCoeff() < o.step_tolerance) return true;
    std::vector<Isometry3d> trial = x;
    for (std::size_t i = 1; i < x.size(); ++i)
      trial[i] =
          ulc::se3_exp(Vec6d(step.segment<6>(static_cast<Eigen::Index>(6 * (i - 1))))) * x[i];
    const double trial_cost = cost(trial);
    const double predicted = -(g.dot(step) + 0.5 * step.dot(H * step));
    const double actual = sums.cost - trial_cost;
    const double rho = predicted > 0.0 ? actual / predicted : -1.0;
    if (rho > 0.0) {
      x = trial;
      const double before = sums.cost;
      sums = evaluate(x);
      mu *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      if (actual < o.cost_tolerance * before) return true;
    } else {
      mu *= nu;
      nu *= 2.0;
    }
  }
  return false;
}

/// Poses in the window frame (the first pose's): the first is exactly the identity.
inline std::vector<Isometry3d> in_window_frame(const std::vector<Isometry3d>& poses_world) {
  const Isometry3d origin_inv = poses_world[0].inverse();
  std::vector<Isometry3d> x(poses_world.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = origin_inv * poses_world[i];
  x[0] = Isometry3d::Identity();
  return x;
}

/// The rounds shared by the window BAs, on the variables x = poses_world in the window frame
/// (in_window_frame): planes extracted from the clouds placed by place(x) (the entries' poses),
/// then LM over x on evaluate(planes, x) (Sums over x). Fills result's poses (back in the
/// world), planes, points, costs, Hessian, noise and status; returns the refined x.
template <class Cloud, class Place, class Evaluate>
std::vector<Isometry3d> run_rounds(const std::vector<const Cloud*>& clouds,
                                   const std::vector<Isometry3d>& poses_world, const Place& place,
                                   const Evaluate& evaluate, const WindowBaOptions& options,
                                   WindowBaResult& result) {
  std::vector<Isometry3d> x = in_window_frame(poses_world);
  const auto to_world = [&] {
    result.poses = poses_world;
    for (std::size_t i = 1; i < x.size(); ++i) result.poses[i] = poses_world[0] * x[i];
  };
  const auto n = static_cast<Eigen::Index>(6 * x.size());
  std::vector<Plane> planes;
  Sums sums;
  bool converged = false;
  for (int round = 0; round < options.rounds; ++round) {
    planes = extract_planes(clouds, place(x), options.planes);
    result.planes = planes.size();
    result.points = 0;
    for (const Plane& p : planes) result.points += p.points;
    if (planes.size() < options.min_planes) {
      result.status = WindowBaStatus::too_few_planes;
      result.reason = "fewer planar cells than min_planes";
      result.hessian = Eigen::MatrixXd::Zero(n, n);
      result.gradient = Eigen::VectorXd::Zero(n);
      to_world();
      return x;
    }
    sums = evaluate(planes, x);
    if (round == 0) result.initial_cost = sums.cost;
    converged = levenberg_marquardt(
        x, sums, [&](const std::vector<Isometry3d>& at) { return evaluate(planes, at); },
        [&](const std::vector<Isometry3d>& at) { return cost(planes, place(at), options); },
        options, result.iterations);
  }
  result.cost = sums.cost;
  result.hessian = sums.H;
  result.gradient = sums.g;
  result.degenerate_planes = sums.degenerate;
  const double dof = static_cast<double>(result.points) - 3.0 * static_cast<double>(result.planes);
  result.noise_variance = dof > 0.0 ? result.cost / dof : 0.0;
  if (!converged && options.max_iterations > 0) {
    result.status = WindowBaStatus::not_converged;
    result.reason = "max_iterations reached before the step or the cost change was small";
  }
  to_world();
  return x;
}

}  // namespace window_ba_detail

/// Refines the poses of frames[1..] with frames[0] fixed (see the header comment).
template <class Cloud>
WindowBaResult window_ba(const std::vector<const Cloud*>& frames,
                         const std::vector<Isometry3d>& poses_world,
                         const WindowBaOptions& options = {}) {
  namespace d = window_ba_detail;
  WindowBaResult result;
  result.poses = poses_world;
  const std::size_t W = frames.size();
  if (W < 2 || poses_world.size() != W || !d::valid_options(options)) {
    result.status = WindowBaStatus::invalid_input;
    result.reason = W < 2 ? "a window needs at least two frames"
                          : "frame and pose counts differ, or bad options";
    return result;
  }
  for (const Isometry3d& T : poses_world) {
    if (!T.matrix().allFinite()) {
      result.status = WindowBaStatus::invalid_input;
      result.reason = "a pose is not finite";
      return result;
    }
  }
  d::run_rounds(
      frames, poses_world, [](const std::vector<Isometry3d>& at) { return at; },
      [&](const std::vector<Plane>& planes, const std::vector<Isometry3d>& at) {
        return d::evaluate(planes, at, options);
      },
      options, result);
  return result;
}

/// window_ba over every frame of a container of clouds.
template <class Cloud>
WindowBaResult window_ba(const std::vector<Cloud>& frames,
                         const std::vector<Isometry3d>& poses_world,
                         const WindowBaOptions& options = {}) {
  std::vector<const Cloud*> views;
  views.reserve(frames.size());
  for (const Cloud& c : frames) views.push_back(&c);
  return window_ba(views, poses_world, options);
}

}  // namespace hots
