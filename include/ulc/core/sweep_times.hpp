// Per-point times from azimuth: for a spinning LiDAR whose driver does not publish a time per
// point (or whose conversion dropped it), the time of a point within the sweep follows from
// its azimuth, as LIO-SAM and FAST-LIO do for such drivers.
//
// Conventions this header owns:
//   - The points are in firing order (as drivers publish a sweep, column after column): the
//     azimuth, unwrapped along the point order, then turns once around, in either direction.
//     The direction of spin is read from the data (the sign of that turn), so clockwise
//     (Velodyne, Ouster, Hesai) and counter-clockwise heads both work.
//   - A frame "looks like a 360-degree sweep" when the unwrapped azimuth turns by one revolution
//     within SweepTimeOptions::revolution_tolerance and never steps back against the spin by
//     more than max_backstep (the lasers' azimuth offsets within a column): a non-repetitive
//     (Livox) or small-FoV pattern fails this and gets no times.
//   - A point's time is its fraction of the revolution from the sweep's first column (the
//     median unwrapped azimuth of its first points, so that one laser's azimuth offset does
//     not shift every time), clamped to [0, 1], times the frame period: seconds since the frame
//     timestamp, as the per-point times every stage reads. Non-finite points and points on the
//     axis get the time of the point before them.
//   - Accuracy: a laser's azimuth offset of o degrees shifts its points by o / 360 of a period
//     (VLP-32C: up to about 1 ms at 10 Hz); tests/core/test_sweep_times.cpp checks the times
//     against the simulator's true ones.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "ulc/core/median.hpp"
#include "ulc/core/point_traits.hpp"

namespace ulc {

struct SweepTimeOptions {
  double revolution_tolerance = 0.08;    ///< |turn / 2 pi - 1| allowed
  double max_backstep = 0.35;            ///< rad against the spin, from the furthest reached
  std::size_t first_column_points = 64;  ///< points whose median azimuth starts the sweep
  std::size_t min_points = 1000;         ///< fewer: not a sweep worth timing
};

/// Times synthesised for one frame, or why there are none.
struct SweepTimes {
  std::vector<double> times;  ///< one per point, seconds since the frame timestamp
  int direction = 0;          ///< +1: azimuth increases with time (counter-clockwise), -1: not
  std::string reason;         ///< why no times (empty when there are)
  bool ok() const { return reason.empty(); }
};

namespace sweep_detail {

constexpr double kTwoPi = 6.283185307179586;

inline double wrap(double a) {
  while (a > kTwoPi / 2) a -= kTwoPi;
  while (a <= -kTwoPi / 2) a += kTwoPi;
  return a;
}

/// The azimuth unwrapped along the point order (NaN for points without one).
template <class Cloud>
std::vector<double> unwrapped_azimuth(const Cloud& cloud, std::size_t& valid) {
  const std::size_t n = traits::size(cloud);
  std::vector<double> u(n, std::nan(""));
  valid = 0;
  double last = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto p = traits::point(cloud, i);
    const double x = static_cast<double>(p.x()), y = static_cast<double>(p.y());
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(static_cast<double>(p.z())) ||
        x * x + y * y < 1e-6)
      continue;
    const double a = std::atan2(y, x);
    u[i] = valid == 0 ? a : last + wrap(a - std::remainder(last, kTwoPi));
    last = u[i];
    ++valid;
  }
  return u;
}

/// The largest step back against the spin: how far the azimuth returns from the furthest point
/// it reached (direction-signed).
inline double largest_backstep(const std::vector<double>& u, int direction) {
  double furthest = -1e300, worst = 0.0;
  for (const double v : u) {
    if (std::isnan(v)) continue;
    const double s = direction * v;
    furthest = std::max(furthest, s);
    worst = std::max(worst, furthest - s);
  }
  return worst;
}

/// Median unwrapped azimuth of the first `count` points that have one.
inline double sweep_start(const std::vector<double>& u, std::size_t count) {
  std::vector<double> first;
  for (std::size_t i = 0; i < u.size() && first.size() < count; ++i)
    if (!std::isnan(u[i])) first.push_back(u[i]);
  return upper_median(std::move(first));
}

}  // namespace sweep_detail

/// Per-point times of a spinning LiDAR's frame from its azimuths (see the top); `period` is the
/// sweep's duration (the frame period), seconds.
template <class Cloud>
SweepTimes sweep_times_from_azimuth(const Cloud& cloud, double period,
                                    const SweepTimeOptions& options = {}) {
  using namespace sweep_detail;
  SweepTimes out;
  if (!(period > 0.0) || !std::isfinite(period)) {
    out.reason = "no frame period";
    return out;
  }
  std::size_t valid = 0;
  const std::vector<double> u = unwrapped_azimuth(cloud, valid);
  if (valid < std::max<std::size_t>(options.min_points, 2)) {
    out.reason = "too few points for a sweep";
    return out;
  }
  auto has_azimuth = [](double v) { return !std::isnan(v); };
  const double first = *std::find_if(u.begin(), u.end(), has_azimuth);
  const double last = *std::find_if(u.rbegin(), u.rend(), has_azimuth);
  const double turn = last - first;
  out.direction = turn >= 0.0 ? 1 : -1;
  if (std::abs(std::abs(turn) / kTwoPi - 1.0) > options.revolution_tolerance) {
    out.reason = "the azimuth turns " + std::to_string(std::abs(turn) / kTwoPi) +
                 " revolutions along the point order, not one (not a 360-degree sweep)";
    return out;
  }
  if (largest_backstep(u, out.direction) > options.max_backstep) {
    out.reason =
        "the azimuth does not advance steadily along the point order (not a spinning "
        "sweep in firing order)";
    return out;
  }
  const double start = sweep_start(u, options.first_column_points);
  out.times.resize(u.size());
  double previous = 0.0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    if (!std::isnan(u[i])) {
      const double fraction = out.direction * (u[i] - start) / kTwoPi;
      previous = std::clamp(fraction, 0.0, 1.0) * period;
    }
    out.times[i] = previous;
  }
  return out;
}

}  // namespace ulc
