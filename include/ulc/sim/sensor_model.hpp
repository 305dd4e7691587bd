// Sensor models: where each ray of a frame points and when it fires, plus the measurement
// imperfections (range noise, jitter, dropout, limits) shared by every model.
//
// Conventions this header owns:
//   - LiDAR frame: x forward, y left, z up. A ray is given by its beam origin in that frame,
//     its nominal azimuth (from +x towards +y) and elevation (above the x-y plane), radians,
//     the matching unit direction d = (cos el cos az, cos el sin az, sin el), and its time in
//     seconds since the frame's first firing.
//   - Rays are indexed in firing order, so times are nondecreasing in the index; a frame holds
//     ray_count() rays spanning one sweep (one revolution, or 1/rate of a scan pattern).
//   - Randomness (azimuth phase of a revolution, pattern phases) comes in through keys, never
//     from a generator: see random.hpp.
//   - Spinning heads rotate clockwise seen from above (azimuth decreases with time), like
//     Velodyne units; each frame starts at the back (azimuth pi) minus a random fraction of
//     one column step, so no two revolutions sample the same azimuths.
//   - Decimation d > 1 keeps every d-th column (spinning) or sample (patterns) with its true
//     time: a cheaper sensor with the same timing, for fast tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "ulc/core/angles.hpp"
#include "ulc/core/types.hpp"
#include "ulc/sim/random.hpp"

namespace ulc::sim {

/// Measurement imperfections and limits of one sensor.
struct RangeModel {
  double min_range = 0.5;    ///< m; closer returns are discarded
  double max_range = 100.0;  ///< m, reached on a surface of reference_reflectivity
  double reference_reflectivity = 0.5;
  double range_sigma = 0.02;                   ///< m, 1 sigma Gaussian range noise
  double range_resolution = 0.002;             ///< m, output quantisation
  double angular_jitter = 0.05 * kPi / 180.0;  ///< rad, 1 sigma per axis
  double base_dropout = 0.02;                  ///< probability of losing any return
};

/// Angular limits of a model's rays, for checks: azimuth and elevation ranges, or a cone of
/// `cone_radius` around +x when cone_radius > 0.
struct FieldOfView {
  double azimuth_min = -kPi, azimuth_max = kPi;
  double elevation_min = -1.5707963267948966, elevation_max = 1.5707963267948966;
  double cone_radius = 0.0;

  /// True when the direction d (LiDAR frame) lies inside the limits widened by `margin` rad.
  bool contains(const Vec3d& d, double margin) const {
    const double el = std::atan2(d.z(), std::hypot(d.x(), d.y()));
    const double az = std::atan2(d.y(), d.x());
    if (cone_radius > 0.0) {
      // Pattern coordinates (az, el) as used by the Risley model.
      return std::hypot(az, el) <= cone_radius + margin;
    }
    return el >= elevation_min - margin && el <= elevation_max + margin &&
           az >= azimuth_min - margin && az <= azimuth_max + margin;
  }
};

struct SensorRay {
  Vec3d origin = Vec3d::Zero();  ///< beam origin, LiDAR frame
  Vec3d dir = Vec3d::UnitX();    ///< nominal unit direction (azimuth, elevation below)
  double azimuth = 0.0;
  double elevation = 0.0;
  double time = 0.0;  ///< seconds since the frame's first firing
};

/// The unit direction of (azimuth, elevation).
inline Vec3d direction_of(double azimuth, double elevation) {
  const double ce = std::cos(elevation);
  return Vec3d(ce * std::cos(azimuth), ce * std::sin(azimuth), std::sin(elevation));
}

/// What a pattern needs to know about one frame.
struct FrameSetup {
  double rate_hz = 10.0;
  double start_time = 0.0;     ///< time of the first firing (true time), for continuous patterns
  double start_azimuth = 0.0;  ///< spinning: head azimuth of the first column
  unsigned decimation = 1;
  std::size_t rays = 0;
};

/// Set-up of a continuously firing scanner: `channels` lasers each firing `per_second` times a
/// second, every `decimation`-th firing kept.
inline FrameSetup continuous_setup(double rate_hz, double start_time, unsigned decimation,
                                   double per_second, std::size_t channels) {
  FrameSetup f;
  f.rate_hz = rate_hz;
  f.start_time = start_time;
  f.decimation = decimation;
  const auto samples = static_cast<std::size_t>(std::floor(per_second / rate_hz));
  f.rays = (samples + decimation - 1) / decimation * channels;
  return f;
}

/// A rotating multi-beam LiDAR (Velodyne, Ouster, Robosense, Hesai).
struct SpinningLidar {
  std::vector<double> elevation_deg;       ///< per laser, laser-id order
  std::vector<double> azimuth_offset_deg;  ///< per laser (empty: none)
  std::vector<int> firing_slot;            ///< per laser: its slot in the firing cycle
  double slot_dt = 0.0;                    ///< s between consecutive slots
  double cycle_s = 55.296e-6;              ///< one column (all slots) when columns follow rate
  int fixed_columns = 0;                   ///< > 0: columns per revolution whatever the rate
  double beam_origin_radius = 0.0;         ///< m, beam origin off the rotation axis

  std::size_t lasers() const { return elevation_deg.size(); }
  std::size_t columns(double rate_hz) const {
    if (fixed_columns > 0) return static_cast<std::size_t>(fixed_columns);
    return static_cast<std::size_t>(std::floor(1.0 / (rate_hz * cycle_s)));
  }
  double column_dt(double rate_hz) const {
    return fixed_columns > 0 ? 1.0 / (rate_hz * fixed_columns) : cycle_s;
  }

  /// Precomputes the firing order; call once after filling the tables.
  void finalize() {
    order_.resize(lasers());
    for (std::size_t i = 0; i < lasers(); ++i) order_[i] = static_cast<int>(i);
    if (firing_slot.size() != lasers()) firing_slot.assign(lasers(), 0);
    std::stable_sort(order_.begin(), order_.end(),
                     [&](int a, int b) { return firing_slot[a] < firing_slot[b]; });
    elevation_rad_.resize(lasers());
    cos_el_.resize(lasers());
    sin_el_.resize(lasers());
    offset_rad_.assign(lasers(), 0.0);
    for (std::size_t i = 0; i < lasers(); ++i) {
      elevation_rad_[i] = elevation_deg[i] * kRadPerDeg;
      cos_el_[i] = std::cos(elevation_rad_[i]);
      sin_el_[i] = std::sin(elevation_rad_[i]);
      if (i < azimuth_offset_deg.size()) offset_rad_[i] = azimuth_offset_deg[i] * kRadPerDeg;
    }
  }

  FrameSetup setup(double rate_hz, double start_time, std::uint64_t frame_key,
                   unsigned decimation) const {
    FrameSetup f;
    f.rate_hz = rate_hz;
    f.start_time = start_time;
    f.decimation = decimation;
    const double step = kTwoPi * rate_hz * column_dt(rate_hz);
    f.start_azimuth = kPi - step * unit_double(mix64(frame_key ^ 0x617a6dULL));
    f.rays = (columns(rate_hz) + decimation - 1) / decimation * lasers();
    return f;
  }

  SensorRay ray(std::size_t i, const FrameSetup& f) const {
    const std::size_t n = lasers();
    const std::size_t column = i / n * f.decimation;
    const std::size_t k = i % n;
    const int laser = order_[k];
    SensorRay r;
    r.time = static_cast<double>(column) * column_dt(f.rate_hz) + firing_slot[laser] * slot_dt;
    const double head = f.start_azimuth - kTwoPi * f.rate_hz * r.time;
    r.azimuth = head + offset_rad_[laser];
    r.elevation = elevation_rad_[laser];
    r.dir = Vec3d(cos_el_[laser] * std::cos(r.azimuth), cos_el_[laser] * std::sin(r.azimuth),
                  sin_el_[laser]);
    if (beam_origin_radius > 0.0)
      r.origin =
          Vec3d(beam_origin_radius * std::cos(head), beam_origin_radius * std::sin(head), 0.0);
    return r;
  }

  FieldOfView fov() const {
    FieldOfView v;
    v.elevation_min = *std::min_element(elevation_deg.begin(), elevation_deg.end()) * kRadPerDeg;
    v.elevation_max = *std::max_element(elevation_deg.begin(), elevation_deg.end()) * kRadPerDeg;
    return v;
  }

  static constexpr double kTwoPi = 2.0 * kPi;

 private:
  std::vector<int> order_;
  std::vector<double> elevation_rad_, cos_el_, sin_el_, offset_rad_;
};

/// A Livox-style non-repetitive scanner: each channel's beam traces the sum of rotating
/// phasors (the small-angle Risley-prism model), p(t) = sum_k a_k exp(i (2 pi f_k t + phi_k)),
/// azimuth = scale_az Re p + channel azimuth offset, elevation = scale_el Im p + channel
/// elevation offset (degrees). The pattern runs continuously across frames from a random
/// power-on phase per sensor, so consecutive frames cover different parts of the field.
struct RisleyLidar {
  struct Prism {
    double amplitude_deg;
    double frequency_hz;
  };
  struct Channel {
    double azimuth_deg;
    double elevation_deg;
  };
  std::vector<Prism> prisms;
  std::vector<Channel> channels = {{0.0, 0.0}};
  double channel_rate_hz = 100000.0;  ///< points per second per channel
  double scale_az = 1.0, scale_el = 1.0;
  bool circular = false;  ///< FoV is the cone of the pattern (Mid-40), else a rectangle

  /// Random prism phases of one power-on session.
  void set_session(std::uint64_t key) {
    phases_.clear();
    for (std::size_t k = 0; k < prisms.size(); ++k)
      phases_.push_back(6.283185307179586 * unit_double(hash_key(key, k, 0x707269ULL)));
  }

  FrameSetup setup(double rate_hz, double start_time, std::uint64_t /*frame_key*/,
                   unsigned decimation) const {
    return continuous_setup(rate_hz, start_time, decimation, channel_rate_hz, channels.size());
  }

  SensorRay ray(std::size_t i, const FrameSetup& f) const {
    const std::size_t c = channels.size();
    const std::size_t sample = i / c * f.decimation;
    const Channel& ch = channels[i % c];
    SensorRay r;
    r.time = static_cast<double>(sample) / channel_rate_hz;
    const double t = f.start_time + r.time;
    double re = 0.0, im = 0.0;
    for (std::size_t k = 0; k < prisms.size(); ++k) {
      const double angle = 6.283185307179586 * prisms[k].frequency_hz * t + phase(k);
      re += prisms[k].amplitude_deg * std::cos(angle);
      im += prisms[k].amplitude_deg * std::sin(angle);
    }
    r.azimuth = (scale_az * re + ch.azimuth_deg) * kRadPerDeg;
    r.elevation = (scale_el * im + ch.elevation_deg) * kRadPerDeg;
    r.dir = direction_of(r.azimuth, r.elevation);
    return r;
  }

  double amplitude_sum() const {
    double s = 0.0;
    for (const Prism& p : prisms) s += std::abs(p.amplitude_deg);
    return s;
  }

  FieldOfView fov() const {
    FieldOfView v;
    const double a = amplitude_sum();
    if (circular) {
      v.cone_radius = a * scale_az * kRadPerDeg;
      return v;
    }
    double az_lo = 0, az_hi = 0, el_lo = 0, el_hi = 0;
    for (const Channel& ch : channels) {
      az_lo = std::min(az_lo, ch.azimuth_deg);
      az_hi = std::max(az_hi, ch.azimuth_deg);
      el_lo = std::min(el_lo, ch.elevation_deg);
      el_hi = std::max(el_hi, ch.elevation_deg);
    }
    v.azimuth_min = (az_lo - scale_az * a) * kRadPerDeg;
    v.azimuth_max = (az_hi + scale_az * a) * kRadPerDeg;
    v.elevation_min = (el_lo - scale_el * a) * kRadPerDeg;
    v.elevation_max = (el_hi + scale_el * a) * kRadPerDeg;
    return v;
  }

 private:
  double phase(std::size_t k) const { return k < phases_.size() ? phases_[k] : 0.0; }
  std::vector<double> phases_;
};

/// A MEMS raster scanner (RS-M1 like): several lasers side by side, each sweeping its own
/// horizontal zone with a resonant (sinusoidal) fast axis while the slow axis steps linearly
/// from top to bottom once per frame.
struct MemsLidar {
  std::vector<double> zone_center_deg = {-48.0, -24.0, 0.0, 24.0, 48.0};
  double zone_half_width_deg = 12.0;
  double elevation_half_deg = 12.5;
  double fast_axis_hz = 630.0;      ///< two lines per period
  double laser_rate_hz = 157500.0;  ///< points per second per laser

  FrameSetup setup(double rate_hz, double start_time, std::uint64_t /*frame_key*/,
                   unsigned decimation) const {
    return continuous_setup(rate_hz, start_time, decimation, laser_rate_hz, zone_center_deg.size());
  }

  SensorRay ray(std::size_t i, const FrameSetup& f) const {
    const std::size_t lasers = zone_center_deg.size();
    const std::size_t sample = i / lasers * f.decimation;
    SensorRay r;
    r.time = static_cast<double>(sample) / laser_rate_hz;
    const double fast = std::sin(6.283185307179586 * fast_axis_hz * (f.start_time + r.time));
    r.azimuth = (zone_center_deg[i % lasers] + zone_half_width_deg * fast) * kRadPerDeg;
    r.elevation = elevation_half_deg * (1.0 - 2.0 * r.time * f.rate_hz) * kRadPerDeg;
    r.dir = direction_of(r.azimuth, r.elevation);
    return r;
  }

  FieldOfView fov() const {
    FieldOfView v;
    v.azimuth_min = (zone_center_deg.front() - zone_half_width_deg) * kRadPerDeg;
    v.azimuth_max = (zone_center_deg.back() + zone_half_width_deg) * kRadPerDeg;
    v.elevation_min = -elevation_half_deg * kRadPerDeg;
    v.elevation_max = elevation_half_deg * kRadPerDeg;
    return v;
  }
};

using ScanPattern = std::variant<SpinningLidar, RisleyLidar, MemsLidar>;

/// A complete sensor: scan pattern, imperfections and housing.
struct SensorModel {
  std::string name;
  ScanPattern pattern;
  RangeModel range;
  Vec3d housing_half = Vec3d(0.05, 0.05, 0.05);  ///< box around the origin that blocks others

  FieldOfView fov() const {
    return std::visit([](const auto& p) { return p.fov(); }, pattern);
  }
  FrameSetup setup(double rate_hz, double start_time, std::uint64_t frame_key,
                   unsigned decimation) const {
    return std::visit(
        [&](const auto& p) { return p.setup(rate_hz, start_time, frame_key, decimation); },
        pattern);
  }
  /// One ray (slow path through the variant; the ray caster visits once per frame instead).
  SensorRay ray(std::size_t i, const FrameSetup& f) const {
    return std::visit([&](const auto& p) { return p.ray(i, f); }, pattern);
  }
  bool is_spinning() const { return std::holds_alternative<SpinningLidar>(pattern); }
};

}  // namespace ulc::sim
