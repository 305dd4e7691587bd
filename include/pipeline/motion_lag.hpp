// The lag between two rigidly mounted LiDARs' motions: their rotation rates and velocities,
// related by the extrinsic, line up only at the clocks' offset.
//
// Conventions this header owns:
//   - Input: each LiDAR's poses at its own frame timestamps (T_map_lidar, any map: only
//     relative motion is used), the timestamps (b's on its own clock) and the extrinsic
//     T_ab = T_base_target (its translation only carries velocities to b's origin, so JEEP's,
//     even a few decimetres off, does).
//   - Motion of frame k over a baseline of about baseline_s: the rotation rate
//     so3_log(R_{k-h}^T R_{k+h}) / dt and the velocity R_k^T (p_{k+h} - p_{k-h}) / dt, in the
//     body frame. A long baseline averages out the fast pitch and roll of bumps, which the two
//     LiDARs' frames sample at different phases (aliasing that looks like a lag).
//   - Rigidly mounted, at the same instant: omega_a = R_ab omega_b and b's origin's speed
//     |v_a + omega_a x t_ab| = |v_b| (the speed, not the velocity vector: the vertical and
//     lateral velocities of bumps are aliased like their rates). With t_base = t_target + lag,
//     a's motion at t_b + lag matches b's at t_b. The residuals are normalised by noise levels (the
//     larger of the residuals' own rms at lag 0 and a floor: the odometries' errors are correlated
//     between LiDARs, so their own residual understates them,
//     docs/experiments/unestimated_clocks.md).
//   - J(lag) = mean of the normalised squared residuals over b's frames whose t_b +- max_lag
//     lie inside a's; grid search, then a parabola through the best grid point's neighbours.
//   - Uncertainty (Gauss-Newton): sigma^2 = c / sum |d(normalised a motion) / dt|^2, with
//     c = baseline / period (neighbouring rates share frames: that many are one sample). A
//     drive at constant speed in a straight line has no such change: sigma is large.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "pipeline/vouch_options.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

struct MotionLag {
  double lag_s = 0.0;  ///< t_base = t_target + lag
  double sigma_s = std::numeric_limits<double>::infinity();
  std::size_t samples = 0;  ///< b's frames compared
};

/// Noise floors of an odometry's motion over a ~1 s baseline, and the search.
namespace lag_detail {

struct Motion {
  std::vector<double> t;
  std::vector<Vec3d> omega, velocity;  ///< body frame
};

inline Motion body_motion(const std::vector<Isometry3d>& poses, const std::vector<double>& t,
                          double baseline_s) {
  Motion m;
  const std::size_t n = std::min(poses.size(), t.size());
  if (n < 3) return m;
  const double period = (t[n - 1] - t[0]) / static_cast<double>(n - 1);
  const std::size_t h = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::lround(0.5 * baseline_s / std::max(period, 1e-6))));
  for (std::size_t k = h; k + h < n; ++k) {
    const double dt = t[k + h] - t[k - h];
    if (!(dt > 0.0)) continue;
    m.t.push_back(t[k]);
    m.omega.push_back(so3_log(Mat3d(poses[k - h].linear().transpose() * poses[k + h].linear())) /
                      dt);
    m.velocity.push_back(poses[k].linear().transpose() *
                         (poses[k + h].translation() - poses[k - h].translation()) / dt);
  }
  return m;
}

/// a's motion at time t (inside [m.t.front(), m.t.back()]) by linear interpolation, with b's
/// origin's velocity v_a + omega_a x t_ab, and the slopes.
struct Sample {
  Vec3d omega, omega_slope;
  double speed = 0.0, speed_slope = 0.0;  ///< of b's origin
};

inline Sample sample_at(const Motion& m, double t, const Vec3d& t_ab) {
  auto it = std::upper_bound(m.t.begin(), m.t.end(), t);
  std::size_t k = static_cast<std::size_t>(it - m.t.begin());
  k = std::clamp<std::size_t>(k, 1, m.t.size() - 1);
  const double span = m.t[k] - m.t[k - 1];
  const double f = span > 0.0 ? (t - m.t[k - 1]) / span : 0.0;
  auto speed = [&](std::size_t i) { return (m.velocity[i] + m.omega[i].cross(t_ab)).norm(); };
  Sample s;
  s.omega = (1.0 - f) * m.omega[k - 1] + f * m.omega[k];
  s.speed = (1.0 - f) * speed(k - 1) + f * speed(k);
  const double inv = span > 0.0 ? 1.0 / span : 0.0;
  s.omega_slope = (m.omega[k] - m.omega[k - 1]) * inv;
  s.speed_slope = (speed(k) - speed(k - 1)) * inv;
  return s;
}

/// b's motion in a's frame, at b's times.
struct Compared {
  std::vector<double> t;
  std::vector<Vec3d> omega;
  std::vector<double> speed;
};

struct Noise {
  double rate = 1.0, velocity = 1.0;
};

inline double cost(const Motion& a, const Compared& b, const Vec3d& t_ab, double lag,
                   const Noise& noise) {
  double sum = 0.0;
  for (std::size_t j = 0; j < b.t.size(); ++j) {
    const Sample s = sample_at(a, b.t[j] + lag, t_ab);
    sum += (s.omega - b.omega[j]).squaredNorm() / (noise.rate * noise.rate) +
           (s.speed - b.speed[j]) * (s.speed - b.speed[j]) / (noise.velocity * noise.velocity);
  }
  return sum / static_cast<double>(b.t.size());
}

/// The residuals' own rms at lag 0, floored.
inline Noise noise_levels(const Motion& a, const Compared& b, const Vec3d& t_ab,
                          const MotionLagOptions& o) {
  double rate = 0.0, velocity = 0.0;
  for (std::size_t j = 0; j < b.t.size(); ++j) {
    const Sample s = sample_at(a, b.t[j], t_ab);
    rate += (s.omega - b.omega[j]).squaredNorm() / 3.0;
    velocity += (s.speed - b.speed[j]) * (s.speed - b.speed[j]);
  }
  const double m = static_cast<double>(b.t.size());
  return {std::max(o.rate_noise, std::sqrt(rate / m)),
          std::max(o.velocity_noise, std::sqrt(velocity / m))};
}

inline Compared compared(const Motion& a, const Motion& b, const Mat3d& R_ab, double max_lag) {
  Compared c;
  for (std::size_t j = 0; j < b.t.size(); ++j)
    if (b.t[j] - max_lag >= a.t.front() && b.t[j] + max_lag <= a.t.back()) {
      c.t.push_back(b.t[j]);
      c.omega.push_back(R_ab * b.omega[j]);
      c.speed.push_back(b.velocity[j].norm());
    }
  return c;
}

}  // namespace lag_detail

/// The lag within +- max_lag (see the top); samples 0 when the motions do not overlap enough.
inline MotionLag estimate_motion_lag(const std::vector<Isometry3d>& poses_a,
                                     const std::vector<double>& times_a,
                                     const std::vector<Isometry3d>& poses_b,
                                     const std::vector<double>& times_b, const Isometry3d& T_ab,
                                     const MotionLagOptions& o) {
  using namespace lag_detail;
  MotionLag out;
  const Motion a = body_motion(poses_a, times_a, o.baseline_s);
  if (a.t.size() < 3 || !(o.step_s > 0.0)) return out;
  const Compared b =
      compared(a, body_motion(poses_b, times_b, o.baseline_s), T_ab.linear(), o.max_lag_s);
  if (b.t.size() < 3) return out;
  const Vec3d t_ab = T_ab.translation();
  const Noise noise = noise_levels(a, b, t_ab, o);
  const int n = static_cast<int>(std::floor(o.max_lag_s / o.step_s));
  int best = -n;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int i = -n; i <= n; ++i) {
    const double c = cost(a, b, t_ab, i * o.step_s, noise);
    if (c < best_cost) best_cost = c, best = i;
  }
  out.lag_s = best * o.step_s;
  if (best > -n && best < n) {  // parabola through the neighbours
    const double cm = cost(a, b, t_ab, (best - 1) * o.step_s, noise);
    const double cp = cost(a, b, t_ab, (best + 1) * o.step_s, noise);
    const double curvature = cm + cp - 2.0 * best_cost;
    if (curvature > 0.0) out.lag_s += 0.5 * o.step_s * (cm - cp) / curvature;
  }
  double information = 0.0;
  for (std::size_t j = 0; j < b.t.size(); ++j) {
    const Sample s = sample_at(a, b.t[j] + out.lag_s, t_ab);
    information += s.omega_slope.squaredNorm() / (noise.rate * noise.rate) +
                   s.speed_slope * s.speed_slope / (noise.velocity * noise.velocity);
  }
  const double m = static_cast<double>(b.t.size());
  const double period = (b.t.back() - b.t.front()) / std::max(1.0, m - 1.0);
  const double correlated = std::max(1.0, o.baseline_s / std::max(period, 1e-6));
  out.samples = b.t.size();
  out.sigma_s = information > 0.0 ? std::sqrt(correlated / information)
                                  : std::numeric_limits<double>::infinity();
  return out;
}

}  // namespace ulc
