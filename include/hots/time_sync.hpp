// Time synchronisation (paper Sec. "Time Synchronization", eq:relationship, eq:var, eq:mean):
// with refined poses of both LiDARs in one world frame, the per-pair extrinsic
//   C_i(dt) = P_a(t_i)^-1 P_b(t_i - dt)
// is constant over i only at the true clock offset dt; elsewhere the motion during dt leaks
// into it. dt* minimises the spread of the C_i (eq:var), and C* is their mean at dt* (eq:mean).
//
// Conventions this header owns:
//   - Poses T_world_a at a's frame times (a's clock) and T_world_b at b's frame times (b's
//     clock), in the same world frame. Clock offset as in docs/design.md: t_a = t_b + dt, so a's
//     instant t_i is b's clock time t_i - dt.
//   - P_b(t) between two b frames: rotation by slerp, translation linear (ulc::interpolate,
//     constant velocity between frames, as the paper's alpha-interpolation).
//   - Spread(dt) = mean_i |t_i - t_mean|^2 + L^2 |log(R_i R_mean^T)|^2 over the a frames whose
//     instant stays inside b's frame span for every dt searched (the set never changes during
//     the search, so the curve is continuous), with R_mean the chordal mean and L =
//     rotation_scale_m turning radians into metres.
//   - Interpolation noise: white pose noise of b adds noise * mean_i((1-alpha_i)^2 + alpha_i^2) to
//     the spread, smallest where a's instants fall halfway between b's frames; left in, it
//     pulls dt* there. Its coefficient is fitted over the grid together with a quadratic in dt
//     and removed from every spread value used below (the "corrected" spread).
//   - Search: dt in [centre - w, centre + w], w = search_periods * a's frame period (median
//     frame spacing): a grid of grid_samples values, then golden-section search between the
//     best sample's neighbours down to tolerance_s.
//   - The minimum is adopted only when it is significant (min_significance); otherwise the
//     offset stays at centre_s and `significant` is false.
//   - Result: C* = (Karcher mean of the rotations, mean translation) at dt*; covariance = the
//     sample covariance of the C_i about C*, as [t_i - t; log(R_i R^T)] (left, [rho; phi]);
//     covariance_of_mean = covariance / n (pairs treated as independent: optimistic when the
//     pose errors of neighbouring frames are correlated).
//   - Nothing here throws or prints. Computations in double whatever the poses' scalar.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/QR>

#include "hots/options.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/median.hpp"
#include "ulc/core/rotation_mean.hpp"
#include "ulc/core/types.hpp"

namespace hots {

using ulc::Isometry3d;
using ulc::Mat3d;
using ulc::Mat6d;
using ulc::Vec3d;
using ulc::Vec6d;

enum class TimeSyncStatus { ok, invalid_input, too_few_pairs, at_search_edge };

inline const char* to_string(TimeSyncStatus s) {
  switch (s) {
    case TimeSyncStatus::ok:
      return "ok";
    case TimeSyncStatus::invalid_input:
      return "invalid_input";
    case TimeSyncStatus::too_few_pairs:
      return "too_few_pairs";
    default:
      return "at_search_edge";
  }
}

struct TimeSyncResult {
  TimeSyncStatus status = TimeSyncStatus::ok;
  const char* reason = "";
  Isometry3d extrinsic = Isometry3d::Identity();  ///< C* = T_base_target (a = base)
  double time_offset_s = 0.0;                     ///< t_a = t_b + time_offset_s
  double spread = 0.0;                            ///< at time_offset_s, m^2
  double spread_at_centre = 0.0;                  ///< at options.centre_s, m^2
  Mat6d covariance = Mat6d::Zero();
  Mat6d covariance_of_mean = Mat6d::Zero();
  std::size_t pairs = 0;
  bool significant = false;    ///< the minimum passed the min_significance test
  double best_offset_s = 0.0;  ///< the curve's minimum, whether significant or not
  int evaluations = 0;
  std::vector<std::pair<double, double>> curve;  ///< (dt, corrected spread) of the grid scan
  double interpolation_noise = 0.0;              ///< fitted per-pair noise of b's poses, m^2

  bool ok() const { return status == TimeSyncStatus::ok; }
};

namespace time_sync_detail {

/// T_world_b at time t (b's clock), interpolated; t must lie within [times.front(), back()].
inline Isometry3d pose_at(const std::vector<double>& times, const std::vector<Isometry3d>& poses,
                          double t) {
  auto it = std::upper_bound(times.begin(), times.end(), t);
  std::size_t j = static_cast<std::size_t>(it - times.begin());
  j = std::clamp<std::size_t>(j, 1, times.size() - 1) - 1;
  const double span = times[j + 1] - times[j];
  const double alpha = span > 0.0 ? (t - times[j]) / span : 0.0;
  return ulc::interpolate(poses[j], poses[j + 1], alpha);
}

struct Problem {
  const std::vector<double>* times_a;
  const std::vector<Isometry3d>* poses_a;
  const std::vector<double>* times_b;
  const std::vector<Isometry3d>* poses_b;
  std::vector<std::size_t> used;  ///< a frames inside b's span for every dt searched
  double scale_sq;

  std::vector<Isometry3d> extrinsics(double dt) const {
    std::vector<Isometry3d> out;
    out.reserve(used.size());
    for (const std::size_t i : used) {
      const double t = (*times_a)[i] - dt;
      out.push_back((*poses_a)[i].inverse() * pose_at(*times_b, *poses_b, t));
    }
    return out;
  }

  static Isometry3d chordal(const std::vector<Isometry3d>& C) {
    std::vector<Mat3d> R;
    Vec3d t = Vec3d::Zero();
    for (const auto& c : C) {
      R.push_back(c.linear());
      t += c.translation();
    }
    Isometry3d mean = Isometry3d::Identity();
    mean.linear() = ulc::chordal_mean(R).rotation;
    mean.translation() = t / static_cast<double>(C.size());
    return mean;
  }

  double spread_about(const std::vector<Isometry3d>& C, const Isometry3d& mean) const {
    double s = 0.0;
    for (const auto& c : C) {
      s += (c.translation() - mean.translation()).squaredNorm() +
           scale_sq * ulc::so3_log(Mat3d(c.linear() * mean.linear().transpose())).squaredNorm();
    }
    return s / static_cast<double>(C.size());
  }

  double spread(double dt) const {
    const auto C = extrinsics(dt);
    return spread_about(C, chordal(C));
  }

  /// mean_i ((1 - alpha_i)^2 + alpha_i^2): how much of b's pose noise survives interpolation at
  /// dt (1 at a frame, 1/2 halfway between two frames).
  double interpolation_gain(double dt) const {
    double g = 0.0;
    for (const std::size_t i : used) {
      const double t = (*times_a)[i] - dt;
      auto it = std::upper_bound(times_b->begin(), times_b->end(), t);
      std::size_t j = static_cast<std::size_t>(it - times_b->begin());
      j = std::clamp<std::size_t>(j, 1, times_b->size() - 1) - 1;
      const double alpha = (t - (*times_b)[j]) / ((*times_b)[j + 1] - (*times_b)[j]);
      g += (1.0 - alpha) * (1.0 - alpha) + alpha * alpha;
    }
    return g / static_cast<double>(used.size());
  }

  /// The spread without the interpolation-noise term, noise * interpolation_gain(dt).
  double corrected(double dt, double noise) const {
    return spread(dt) - noise * interpolation_gain(dt);
  }
};

/// Least-squares fit of the grid spread to p0 + p1 x + p2 x^2 + noise * gain: returns the
/// noise coefficient (>= 0). White pose noise of b enters the spread as noise * gain(dt), which
/// dips wherever a's instants fall halfway between b's frames and would pull dt* there.
inline double fit_interpolation_noise(const std::vector<std::pair<double, double>>& curve,
                                      const std::vector<double>& gain, double centre,
                                      double width) {
  const auto n = static_cast<Eigen::Index>(curve.size());
  Eigen::MatrixXd A(n, 4);
  Eigen::VectorXd y(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double x =
        width > 0.0 ? (curve[static_cast<std::size_t>(k)].first - centre) / width : 0.0;
    A.row(k) << 1.0, x, x * x, gain[static_cast<std::size_t>(k)];
    y[k] = curve[static_cast<std::size_t>(k)].second;
  }
  const Eigen::VectorXd p = A.colPivHouseholderQr().solve(y);
  return p.allFinite() ? std::max(p[3], 0.0) : 0.0;
}

}  // namespace time_sync_detail

/// Clock offset and extrinsic from two refined trajectories (see the header comment).
template <typename S>
TimeSyncResult time_sync(const std::vector<double>& times_a,
                         const std::vector<ulc::Isometry3<S>>& poses_a_in,
                         const std::vector<double>& times_b,
                         const std::vector<ulc::Isometry3<S>>& poses_b_in,
                         const TimeSyncOptions& options = {}) {
  namespace d = time_sync_detail;
  TimeSyncResult result;
  auto fail = [&](TimeSyncStatus s, const char* why) {
    result.status = s;
    result.reason = why;
    return result;
  };
  if (times_a.size() != poses_a_in.size() || times_b.size() != poses_b_in.size() ||
      times_a.size() < 2 || times_b.size() < 2)
    return fail(TimeSyncStatus::invalid_input, "need two or more poses and one time per pose");
  if (options.grid_samples < 3 || !(options.search_periods >= 0.0) ||
      !(options.tolerance_s > 0.0) || !std::isfinite(options.centre_s) ||
      !(options.rotation_scale_m >= 0.0) || !(options.min_significance >= 0.0))
    return fail(TimeSyncStatus::invalid_input, "bad options");
  for (std::size_t i = 1; i < times_b.size(); ++i)
    if (!(times_b[i] > times_b[i - 1]))
      return fail(TimeSyncStatus::invalid_input, "b's times must increase strictly");
  for (std::size_t i = 0; i < times_a.size(); ++i)
    if (!std::isfinite(times_a[i]))
      return fail(TimeSyncStatus::invalid_input, "a's times must be finite");
  std::vector<Isometry3d> poses_a, poses_b;
  for (const auto& T : poses_a_in) poses_a.push_back(T.template cast<double>());
  for (const auto& T : poses_b_in) poses_b.push_back(T.template cast<double>());
  for (const auto& T : poses_a)
    if (!T.matrix().allFinite()) return fail(TimeSyncStatus::invalid_input, "a pose is not finite");
  for (const auto& T : poses_b)
    if (!T.matrix().allFinite()) return fail(TimeSyncStatus::invalid_input, "a pose is not finite");

  const double width = options.search_periods * ulc::median_step(times_a);
  const double lo = options.centre_s - width, hi = options.centre_s + width;
  d::Problem problem{&times_a, &poses_a, &times_b,
                     &poses_b, {},       options.rotation_scale_m * options.rotation_scale_m};
  for (std::size_t i = 0; i < times_a.size(); ++i) {
    // t_i - dt must stay in b's span for dt in [lo, hi].
    if (times_a[i] - hi >= times_b.front() && times_a[i] - lo <= times_b.back())
      problem.used.push_back(i);
  }
  result.pairs = problem.used.size();
  if (problem.used.size() < std::max<std::size_t>(options.min_pairs, 2))
    return fail(TimeSyncStatus::too_few_pairs, "too few a frames overlap b's time span");

  // Coarse grid; the interpolation-noise term is fitted over it and removed; then golden
  // section on the corrected spread between the best sample's neighbours.
  const int n = options.grid_samples;
  std::vector<std::pair<double, double>> raw;
  std::vector<double> gain;
  for (int k = 0; k < n; ++k) {
    const double dt = lo + (hi - lo) * k / (n - 1);
    raw.emplace_back(dt, problem.spread(dt));
    gain.push_back(problem.interpolation_gain(dt));
    ++result.evaluations;
  }
  const double noise = d::fit_interpolation_noise(raw, gain, options.centre_s, width);
  result.interpolation_noise = noise;
  const auto spread = [&](double dt) { return problem.corrected(dt, noise); };
  int best = 0;
  for (int k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    result.curve.emplace_back(raw[i].first, raw[i].second - noise * gain[i]);
    if (result.curve[i].second < result.curve[static_cast<std::size_t>(best)].second) best = k;
  }
  double a = result.curve[static_cast<std::size_t>(std::max(best - 1, 0))].first;
  double b = result.curve[static_cast<std::size_t>(std::min(best + 1, n - 1))].first;
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = b - phi * (b - a), x2 = a + phi * (b - a);
  double f1 = spread(x1), f2 = spread(x2);
  result.evaluations += 2;
  while (b - a > options.tolerance_s) {
    if (f1 <= f2) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - phi * (b - a);
      f1 = spread(x1);
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + phi * (b - a);
      f2 = spread(x2);
    }
    ++result.evaluations;
  }
  double dt = 0.5 * (a + b);
  // The grid's best sample wins if the refined point is somehow worse (flat or noisy curve).
  const auto& grid_best = result.curve[static_cast<std::size_t>(best)];
  if (spread(dt) > grid_best.second) dt = grid_best.first;
  result.best_offset_s = dt;
  result.spread_at_centre = spread(options.centre_s);
  const double n_pairs = static_cast<double>(problem.used.size());
  const double at_best = std::max(spread(dt), 0.0);
  result.significant = n_pairs * (result.spread_at_centre - at_best) >
                       options.min_significance * std::max(at_best, 1e-300);
  if (!result.significant) dt = options.centre_s;
  result.time_offset_s = dt;

  // eq:mean at dt*: Karcher mean of the rotations, mean translation.
  const auto C = problem.extrinsics(dt);
  std::vector<Mat3d> R;
  Vec3d t = Vec3d::Zero();
  for (const auto& c : C) {
    R.push_back(c.linear());
    t += c.translation();
  }
  result.extrinsic.linear() = ulc::karcher_mean(R).rotation;
  result.extrinsic.translation() = t / static_cast<double>(C.size());
  result.spread = problem.spread_about(C, result.extrinsic);
  for (const auto& c : C) {
    Vec6d dev;
    dev.head<3>() = c.translation() - result.extrinsic.translation();
    dev.tail<3>() = ulc::so3_log(Mat3d(c.linear() * result.extrinsic.linear().transpose()));
    result.covariance += dev * dev.transpose();
  }
  const double count = static_cast<double>(C.size());
  result.covariance /= std::max(count - 1.0, 1.0);
  result.covariance_of_mean = result.covariance / count;
  if (result.significant && (best == 0 || best == n - 1)) {
    result.status = TimeSyncStatus::at_search_edge;
    result.reason = "the spread is smallest at the edge of the searched offsets";
  }
  return result;
}

}  // namespace hots
