// Deskewing: undo the motion distortion of a scan under constant velocity.
//
// Conventions this header owns:
//   - A LiDAR sweep starts at the frame timestamp. `sweep_motion` is the sensor's motion over
//     the sweep, T_start_end: the pose at the sweep's end expressed in the pose at its start.
//   - Constant velocity means a constant body-frame twist: the pose at fraction f of the sweep
//     is T_start_f = exp(f * log(sweep_motion)) (f = 0 at the start, 1 at the end; values
//     outside [0, 1] extrapolate).
//   - Deskewing moves a point measured at fraction f into the sensor frame at the sweep start
//     (the frame timestamp): p' = T_start_f * p. Deskewed points all belong to that instant.
//   - A twist xi (per second, [rho; phi] as in lie.hpp) gives sweep_motion = exp(duration xi):
//     see sweep_motion_from_twist.
//   - For speed, the motion is tabulated at kSweepKnots + 1 fractions in [0, 1] and linearly
//     interpolated between them (exact at the knots; the error is below
//     theta^2 / (8 kSweepKnots^2) * range for a sweep rotation theta: 1e-6 m at 100 m for
//     theta = 5 deg). Fractions outside [0, 1] are computed exactly.
//   - Per-point work only (no sums): the result is the same for any number of threads.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ulc/core/cloud.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// exp(duration * twist): the motion over a sweep of `duration` seconds at constant velocity.
inline Isometry3d sweep_motion_from_twist(const Vec6d& twist, double duration) {
  return se3_exp(Vec6d(duration * twist));
}

/// The pose at any fraction of a sweep, T_start_f, tabulated for fast per-point use.
class SweepMotion {
 public:
  static constexpr std::size_t kSweepKnots = 256;

  explicit SweepMotion(const Isometry3d& sweep_motion = Isometry3d::Identity())
      : log_(se3_log(sweep_motion)) {
    identity_ = log_.squaredNorm() == 0.0;
    for (std::size_t i = 0; i <= kSweepKnots; ++i) {
      const Isometry3d T = exact(static_cast<double>(i) / kSweepKnots);
      rotation_[i] = T.linear();
      translation_[i] = T.translation();
    }
  }

  bool is_identity() const { return identity_; }

  /// T_start_f computed exactly.
  Isometry3d exact(double fraction) const { return se3_exp(Vec6d(fraction * log_)); }

  /// T_start_f * p.
  template <typename S>
  Vec3<S> apply(double fraction, const Vec3<S>& p) const {
    if (identity_) return p;
    const Vec3d q = p.template cast<double>();
    if (!(fraction >= 0.0 && fraction <= 1.0)) return (exact(fraction) * q).template cast<S>();
    const double x = fraction * kSweepKnots;
    std::size_t i = static_cast<std::size_t>(x);
    if (i >= kSweepKnots) i = kSweepKnots - 1;
    const double a = x - static_cast<double>(i);
    const Vec3d p0 = rotation_[i] * q + translation_[i];
    const Vec3d p1 = rotation_[i + 1] * q + translation_[i + 1];
    return ((1.0 - a) * p0 + a * p1).template cast<S>();
  }

 private:
  Vec6d log_;
  bool identity_ = true;
  std::array<Mat3d, kSweepKnots + 1> rotation_;
  std::array<Vec3d, kSweepKnots + 1> translation_;
};

namespace detail {
constexpr std::size_t kDeskewGrain = 4096;
}

/// Deskews `points` in place; fractions[i] is point i's fraction of the sweep.
template <typename S>
void deskew_points(std::vector<Vec3<S>>& points, const std::vector<double>& fractions,
                   const Isometry3d& sweep_motion) {
  const SweepMotion motion(sweep_motion);
  if (motion.is_identity() || fractions.size() != points.size()) return;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), detail::kDeskewGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        points[i] = motion.apply(fractions[i], points[i]);
                    });
}

/// A deskewed copy of `cloud` (points at the frame timestamp), fraction = time / sweep_duration.
/// Intensities are kept; per-point times are dropped (they no longer describe the points).
/// A cloud without per-point times, or a sweep_duration that is not positive, is copied as is.
template <class Cloud>
PointCloud<traits::scalar_t<Cloud>> deskew(const Cloud& cloud, const Isometry3d& sweep_motion,
                                           double sweep_duration) {
  using S = traits::scalar_t<Cloud>;
  const std::size_t n = traits::size(cloud);
  PointCloud<S> out;
  out.points.resize(n);
  if (traits::has_intensity(cloud)) {
    out.intensities.resize(n);
    for (std::size_t i = 0; i < n; ++i) out.intensities[i] = traits::intensity(cloud, i);
  }
  const bool timed =
      traits::has_time(cloud) && sweep_duration > 0.0 && std::isfinite(sweep_duration);
  const SweepMotion motion(sweep_motion);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, detail::kDeskewGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const Vec3<S> p = traits::point(cloud, i);
                        out.points[i] =
                            timed ? motion.apply(traits::time(cloud, i) / sweep_duration, p) : p;
                      }
                    });
  return out;
}

}  // namespace ulc
