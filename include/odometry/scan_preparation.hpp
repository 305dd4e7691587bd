// Preparing a LiDAR frame for odometry: range gate, deskew, two voxel resolutions.
//
// Conventions this header owns:
//   - Motion: a constant body-frame twist xi (per second, [rho; phi]) of the LiDAR over its
//     sweep, so a point measured t seconds after the frame timestamp is deskewed by exp(t xi)
//     (deskew.hpp with sweep_motion = exp(duration xi), fraction = t / duration). Prepared
//     points are all in the LiDAR frame at the frame timestamp.
//   - Points outside [min_range, max_range] from the sensor (measured before deskewing, as the
//     sensor measured them) and non-finite points are dropped: the near gate removes the
//     vehicle's own returns and nearby clutter, the far gate the sparse, noisy far field.
//   - Two resolutions: `dense` (centroids of map_voxel voxels) builds maps; `sparse` (the dense
//     points again at registration_voxel) is what gets registered. Both keep
//     voxel_downsample's deterministic order.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "odometry/options.hpp"
#include "ulc/core/cloud.hpp"
#include "ulc/core/deskew.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace odometry {

inline bool valid_scan_options(const ScanOptions& o) {
  return o.min_range >= 0.0 && o.max_range > o.min_range && o.map_voxel > 0.0 &&
         std::isfinite(o.map_voxel) && o.registration_voxel > 0.0 &&
         std::isfinite(o.registration_voxel);
}

template <typename S>
struct PreparedScan {
  std::vector<ulc::Vec3<S>> dense;
  std::vector<ulc::Vec3<S>> sparse;
  std::size_t raw_points = 0;             ///< points of the frame before any filtering
  ulc::Vec6d twist = ulc::Vec6d::Zero();  ///< the twist the points were deskewed with
  double duration = 0.0;                  ///< the sweep duration (frame period) used
};

/// Deskews `cloud` with twist `xi` (per second) over a sweep of `duration` seconds (the frame
/// period) and downsamples it. With options.deskew off, or no per-point times, no deskew.
template <typename S, class Cloud>
PreparedScan<S> prepare_scan(const Cloud& cloud, const ulc::Vec6d& xi, double duration,
                             const ScanOptions& options) {
  PreparedScan<S> out;
  const std::size_t n = ulc::traits::size(cloud);
  out.raw_points = n;
  out.duration = duration;
  ulc::PointCloud<S> kept;
  kept.points.reserve(n);
  const bool timed = options.deskew && ulc::traits::has_time(cloud) && duration > 0.0;
  if (timed) kept.times.reserve(n);
  const double lo2 = options.min_range * options.min_range;
  const double hi2 = options.max_range * options.max_range;
  for (std::size_t i = 0; i < n; ++i) {
    const ulc::Vec3<S> p = ulc::traits::point(cloud, i).template cast<S>();
    const double r2 = p.template cast<double>().squaredNorm();
    if (!(r2 >= lo2 && r2 <= hi2)) continue;  // also drops NaN
    kept.points.push_back(p);
    if (timed) kept.times.push_back(ulc::traits::time(cloud, i));
  }
  if (timed) out.twist = xi;
  const ulc::PointCloud<S> straight =
      timed ? ulc::deskew(kept, ulc::sweep_motion_from_twist(xi, duration), duration) : kept;
  auto dense = ulc::voxel_downsample(straight, options.map_voxel);
  out.dense = std::move(dense.cloud.points);
  ulc::PointCloud<S> dense_cloud;
  dense_cloud.points = out.dense;
  out.sparse =
      std::move(ulc::voxel_downsample(dense_cloud, options.registration_voxel).cloud.points);
  return out;
}

}  // namespace odometry
