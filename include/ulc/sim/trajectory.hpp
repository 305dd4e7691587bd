// Continuous-time vehicle motion along a route: speed changes, turns, terrain pitch and roll,
// body pitch and roll from acceleration, road bumps, and optional lift-platform motion.
//
// Conventions this header owns:
//   - Vehicle frame: x forward, y left, z up; origin on the ground below the rear axle.
//     pose(t) is T_world_vehicle at time t (seconds of true time, which is the clock of every
//     LiDAR whose clock offset is zero; see scenario.hpp).
//   - Orientation is R = Rz(yaw) Ry(pitch) Rx(roll) (ulc::rotation_from_rpy): yaw is the route
//     heading (of the route averaged over steering_ramp_m when that is > 0, with its kappa); pitch
//     = -atan(ground slope ahead) - pitch_per_accel * a (the nose dips when braking) + bump and
//     vibration terms; roll = atan(ground slope to the left) + roll_per_lateral_accel * v^2 kappa
//     (the body leans out of turns) + vibration.
//   - The speed is simulated once at kControlDt with acceleration limits and a look-ahead
//     braking profile for turns and random slow-downs, then stored at kTableDt; s(t) is the
//     cubic Hermite through (s, v) samples, so position and velocity are continuous and
//     pose(t) is exact at any t (no per-frame approximation).
//   - PoseTable samples pose(t) densely (1 ms) for the ray caster's per-point poses; its linear
//     interpolation is within ~1e-6 m and ~1e-7 rad of pose(t).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"
#include "ulc/sim/ground.hpp"
#include "ulc/sim/path.hpp"
#include "ulc/sim/random.hpp"

namespace ulc::sim {

struct MotionSpec {
  double min_speed = 3.0;                 ///< m/s
  double max_speed = 12.0;                ///< m/s
  double max_accel = 1.5;                 ///< m/s^2
  double max_decel = 2.5;                 ///< m/s^2
  double lateral_accel = 2.0;             ///< comfortable m/s^2 in turns (sets turn speeds)
  double slowdowns_per_km = 4.0;          ///< random slow-downs to near min_speed (traffic)
  bool bumps = true;                      ///< speed bumps and road vibration
  double pitch_per_accel = 0.006;         ///< rad per m/s^2
  double roll_per_lateral_accel = 0.008;  ///< rad per m/s^2
  double lift_amplitude = 0.0;            ///< m; > 0 adds a vertical platform motion (bucket truck)
  double lift_period = 30.0;              ///< s, one up-and-down cycle
  /// m; > 0: the vehicle follows the route's moving average over this length
  /// (Path2d::averaged), so its yaw rate and body roll ramp in over it where a line meets an
  /// arc, as on a clothoid, instead of stepping there (0: the route's lines and arcs as they
  /// are). The speed profile stays that of the route; on the averaged path the vehicle is up
  /// to a few per cent slower in tight turns (the chord is shorter than the arc).
  double steering_ramp_m = 0.0;
};

class VehicleTrajectory {
 public:
  static constexpr double kControlDt = 1e-3;
  static constexpr double kTableDt = 5e-3;

  VehicleTrajectory() = default;

  /// Plans the drive along `route` for `duration` seconds (the route must be long enough for
  /// max_speed * duration; the vehicle simply continues straight beyond its end).
  VehicleTrajectory(const Path2d& route, const GroundRelief& ground, const MotionSpec& motion,
                    std::uint64_t key, double duration)
      : route_(route), ground_(ground), motion_(motion), duration_(duration) {
    CounterRng rng(hash_key(key, 0x7472616aULL));
    plan_speed_limits(rng);
    simulate_speed();
    if (motion_.bumps) {
      for (double s = rng.uniform(40.0, 120.0); s < route_.length() + 200.0;
           s += rng.uniform(80.0, 220.0))
        bumps_.push_back(s);
      for (int k = 0; k < 3; ++k)
        vibration_[k] = {6.2831853 / rng.uniform(2.0, 9.0), rng.uniform(0.0, 6.2831853),
                         rng.uniform(0.5, 1.5)};
    }
  }

  double duration() const { return duration_; }
  const Path2d& route() const { return route_; }
  const MotionSpec& motion() const { return motion_; }

  /// Hold the vehicle at its pose of time t for ever (static-vehicle runs).
  void freeze_at(double t) { frozen_ = t; }
  std::optional<double> frozen_at() const { return frozen_; }

  /// Distance driven along the route, metres.
  double distance(double t) const {
    if (frozen_) t = *frozen_;
    std::size_t k;
    double u;
    locate(t, k, u);
    const double h00 = (1 + 2 * u) * (1 - u) * (1 - u), h10 = u * (1 - u) * (1 - u);
    const double h01 = u * u * (3 - 2 * u), h11 = u * u * (u - 1);
    return h00 * s_[k] + h10 * kTableDt * v_[k] + h01 * s_[k + 1] + h11 * kTableDt * v_[k + 1];
  }

  /// Speed, m/s (zero when frozen).
  double speed(double t) const {
    if (frozen_) return 0.0;
    std::size_t k;
    double u;
    locate(t, k, u);
    const double d00 = 6 * u * u - 6 * u, d10 = 3 * u * u - 4 * u + 1;
    const double d01 = -d00, d11 = 3 * u * u - 2 * u;
    return (d00 * s_[k] + d01 * s_[k + 1]) / kTableDt + d10 * v_[k] + d11 * v_[k + 1];
  }

  /// Longitudinal acceleration, m/s^2 (the controller's state, linearly interpolated).
  double acceleration(double t) const {
    if (frozen_) t = *frozen_;
    std::size_t k;
    double u;
    locate(t, k, u);
    return (1 - u) * a_[k] + u * a_[k + 1];
  }

  /// T_world_vehicle at time t.
  Isometry3d pose(double t) const {
    if (frozen_) t = *frozen_;
    const double s = distance(t);
    const double v = frozen_ ? 0.0 : speed(t);  // parked: no body dynamics
    const double a = frozen_ ? 0.0 : acceleration(t);
    const PathPoint p = route_.averaged(s, motion_.steering_ramp_m);
    const double ch = std::cos(p.heading), sh = std::sin(p.heading);
    const Eigen::Vector2d grad = ground_.gradient(p.position.x(), p.position.y());
    double z = ground_.height(p.position.x(), p.position.y());
    double pitch = -std::atan(grad.x() * ch + grad.y() * sh) - motion_.pitch_per_accel * a;
    double roll = std::atan(-grad.x() * sh + grad.y() * ch) +
                  motion_.roll_per_lateral_accel * v * v * p.curvature;
    if (motion_.bumps) add_bumps(s, z, pitch, roll);
    if (motion_.lift_amplitude > 0.0)
      z += motion_.lift_amplitude * 0.5 *
           (1.0 - std::cos(6.283185307179586 * t / motion_.lift_period));
    Isometry3d T = Isometry3d::Identity();
    T.linear() = rotation_from_rpy(roll, pitch, p.heading);
    T.translation() = Vec3d(p.position.x(), p.position.y(), z);
    return T;
  }

 private:
  struct Wave {
    double k = 0.0, phase = 0.0, scale = 0.0;
  };

  void locate(double t, std::size_t& k, double& u) const {
    const double x = std::clamp(t, 0.0, (s_.size() - 1) * kTableDt) / kTableDt;
    k = std::min(static_cast<std::size_t>(x), s_.size() - 2);
    u = x - static_cast<double>(k);
  }

  void add_bumps(double s, double& z, double& pitch, double& roll) const {
    constexpr double kLength = 3.0, kHeight = 0.06;
    auto it = std::upper_bound(bumps_.begin(), bumps_.end(), s);
    if (it != bumps_.begin()) {
      const double u = s - *(it - 1);
      if (u < kLength) {
        const double w = 6.283185307179586 * u / kLength;
        z += kHeight * 0.5 * (1.0 - std::cos(w));
        // The suspension passes about half of the road's slope to the body.
        pitch -= 0.5 * std::atan(kHeight * 0.5 * std::sin(w) * 6.283185307179586 / kLength);
      }
    }
    const Wave& a = vibration_[0];
    const Wave& b = vibration_[1];
    const Wave& c = vibration_[2];
    z += 0.004 * a.scale * std::sin(a.k * s + a.phase) +
         0.003 * b.scale * std::sin(b.k * s + b.phase);
    pitch += 0.0012 * b.scale * std::sin(b.k * s + c.phase) + 0.0008 * c.scale * std::sin(c.k * s);
    roll += 0.0010 * c.scale * std::sin(c.k * s + a.phase) + 0.0006 * a.scale * std::sin(a.k * s);
  }

  /// Speed limit along the route on a 0.5 m grid: random cruise speeds, turn limits, random
  /// slow-downs, then a backward pass so that braking starts early enough.
  void plan_speed_limits(CounterRng& rng) {
    const double length = route_.length() + 500.0;
    const auto n = static_cast<std::size_t>(length / kLimitDs) + 2;
    limit_.assign(n, motion_.max_speed);
    const double low =
        std::max(motion_.min_speed, 0.5 * (motion_.min_speed + motion_.max_speed) - 2.0);
    for (double s = 0.0; s < length;) {  // cruise speed per stretch
      const double stretch = rng.uniform(60.0, 220.0);
      const double cruise = rng.uniform(low, motion_.max_speed);
      for (double u = s; u < std::min(s + stretch, length); u += kLimitDs)
        limit_[index(u)] = cruise;
      s += stretch;
    }
    const double slow_every = 1000.0 / std::max(motion_.slowdowns_per_km, 1e-6);
    for (double s = rng.uniform(0.3, 1.0) * slow_every; s < length;
         s += rng.uniform(0.5, 1.5) * slow_every) {
      const double v = rng.uniform(motion_.min_speed, motion_.min_speed + 2.0);
      const double span = rng.uniform(8.0, 30.0);
      for (double u = s; u < std::min(s + span, length); u += kLimitDs)
        limit_[index(u)] = std::min(limit_[index(u)], v);
    }
    for (std::size_t i = 0; i < n; ++i) {
      const double kappa = std::abs(route_.at(i * kLimitDs).curvature);
      if (kappa > 1e-9)
        limit_[i] = std::min(limit_[i],
                             std::max(motion_.min_speed, std::sqrt(motion_.lateral_accel / kappa)));
    }
    const double plan_decel = 0.6 * motion_.max_decel;
    for (std::size_t i = n - 1; i-- > 0;)
      limit_[i] = std::min(limit_[i],
                           std::sqrt(limit_[i + 1] * limit_[i + 1] + 2.0 * plan_decel * kLimitDs));
  }

  std::size_t index(double s) const {
    return std::min(static_cast<std::size_t>(std::max(s, 0.0) / kLimitDs), limit_.size() - 1);
  }

  /// Tracks the limit ahead with a first-order speed loop and a smoothed acceleration.
  void simulate_speed() {
    const double horizon = duration_ + 1.0;
    const auto steps = static_cast<std::size_t>(horizon / kControlDt) + 1;
    const auto every = static_cast<std::size_t>(std::lround(kTableDt / kControlDt));
    double s = 0.0, v = std::clamp(limit_[0], motion_.min_speed, motion_.max_speed), a = 0.0;
    for (std::size_t i = 0; i <= steps; ++i) {
      if (i % every == 0) {
        s_.push_back(s);
        v_.push_back(v);
        a_.push_back(a);
      }
      const double look = s + v * 0.8;  // react to what is a little ahead
      const double target = std::min(limit_[index(s)], limit_[index(look)]);
      const double a_cmd = std::clamp((target - v) / 1.2, -motion_.max_decel, motion_.max_accel);
      a += (a_cmd - a) * (kControlDt / 0.4);
      v = std::clamp(v + a * kControlDt, motion_.min_speed, motion_.max_speed);
      s += v * kControlDt;
    }
    if (s_.size() < 2) {
      s_.push_back(s);
      v_.push_back(v);
      a_.push_back(a);
    }
  }

  static constexpr double kLimitDs = 0.5;

  Path2d route_;
  GroundRelief ground_;
  MotionSpec motion_;
  double duration_ = 0.0;
  std::optional<double> frozen_;
  std::vector<double> limit_;
  std::vector<double> s_, v_, a_;
  std::vector<double> bumps_;
  Wave vibration_[3];
};

/// Dense samples of T_world_vehicle for fast per-point interpolation: rotation matrices and
/// translations every kDt, interpolated linearly (over 1 ms the chord of the rotation deviates
/// from the arc by ~(omega dt)^2 / 8 < 1e-7 rad: far below any sensor's resolution).
class PoseTable {
 public:
  static constexpr double kDt = 1e-3;

  PoseTable() = default;
  PoseTable(const VehicleTrajectory& trajectory, double t0, double t1) {
    rebuild(trajectory, t0, t1);
  }

  /// Samples [t0, t1] (reusing the storage: one table per frame keeps memory bounded).
  void rebuild(const VehicleTrajectory& trajectory, double t0, double t1) {
    t0_ = t0;
    const auto n = static_cast<std::size_t>(std::ceil((t1 - t0) / kDt)) + 2;
    samples_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Isometry3d T = trajectory.pose(t0 + static_cast<double>(i) * kDt);
      samples_[i].R = T.linear();
      samples_[i].p = T.translation();
    }
  }

  /// Rotation and translation of T_world_vehicle at t (clamped to the table).
  void at(double t, Mat3d& R, Vec3d& p) const {
    const double x = std::clamp((t - t0_) / kDt, 0.0, static_cast<double>(samples_.size() - 1));
    const std::size_t k = std::min(static_cast<std::size_t>(x), samples_.size() - 2);
    const double u = x - static_cast<double>(k);
    const Sample& a = samples_[k];
    const Sample& b = samples_[k + 1];
    R = a.R + u * (b.R - a.R);
    p = a.p + u * (b.p - a.p);
  }

 private:
  struct Sample {
    Mat3d R;
    Vec3d p;
  };
  double t0_ = 0.0;
  std::vector<Sample> samples_;
};

}  // namespace ulc::sim
