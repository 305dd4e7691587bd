// voxel_downsample(cloud, size): one point per occupied voxel, at the centroid of its points.
//
// Conventions this header owns:
//   - Voxels are those of voxel.hpp (floor(p / size), int32 keys).
//   - Output order: voxels in the order of their first point in the input (the lowest index).
//   - Sums are taken in double, in input order within each voxel, then divided and cast to the
//     cloud's scalar: the result is bit-identical for any number of threads.
//   - Intensity and per-point time are averaged too when the input carries them; the output
//     then carries them as well.
//   - Points whose voxel cannot be formed (NaN, Inf, or too far for int32 voxel coordinates)
//     are skipped and counted in `skipped`; they never abort the call.
//   - A voxel size that is not a finite positive number gives status invalid_voxel_size and an
//     empty cloud.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ulc/core/cloud.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"
#include "ulc/core/voxel.hpp"

namespace ulc {

enum class VoxelDownsampleStatus { ok, invalid_voxel_size };

template <typename S>
struct VoxelDownsampleResult {
  VoxelDownsampleStatus status = VoxelDownsampleStatus::ok;
  const char* reason = "";
  PointCloud<S> cloud;               ///< one centroid per occupied voxel
  std::vector<std::uint32_t> count;  ///< input points per output point
  std::size_t skipped = 0;           ///< input points with unusable coordinates

  bool ok() const { return status == VoxelDownsampleStatus::ok; }
};

namespace detail {

struct VoxelSums {
  Vec3<double> point = Vec3<double>::Zero();
  double intensity = 0.0;
  double time = 0.0;
  std::uint32_t count = 0;
};

// Keys are the per-point work worth spreading over threads; grouping is a serial pass in input
// order, which is what makes output order and sums independent of the thread count.
constexpr std::size_t kVoxelKeyGrain = 4096;

}  // namespace detail

template <class Cloud>
VoxelDownsampleResult<traits::scalar_t<Cloud>> voxel_downsample(const Cloud& cloud,
                                                                double voxel_size) {
  using S = traits::scalar_t<Cloud>;
  VoxelDownsampleResult<S> result;
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size)) {
    result.status = VoxelDownsampleStatus::invalid_voxel_size;
    result.reason = "voxel size must be a finite positive number";
    return result;
  }

  const std::size_t n = traits::size(cloud);
  std::vector<VoxelKey> keys(n);
  std::vector<std::uint8_t> usable(n, 0);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, detail::kVoxelKeyGrain),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const auto key = make_voxel_key(traits::point(cloud, i), voxel_size);
          if (key) {
            keys[i] = *key;
            usable[i] = 1;
          }
        }
      },
      tbb::simple_partitioner());

  const bool with_intensity = traits::has_intensity(cloud);
  const bool with_time = traits::has_time(cloud);
  VoxelMap<detail::VoxelSums> voxels;
  voxels.reserve(n / 4 + 16);
  for (std::size_t i = 0; i < n; ++i) {
    if (!usable[i]) {
      ++result.skipped;
      continue;
    }
    detail::VoxelSums& sums = voxels[keys[i]];
    sums.point += traits::point(cloud, i).template cast<double>();
    if (with_intensity) sums.intensity += static_cast<double>(traits::intensity(cloud, i));
    if (with_time) sums.time += traits::time(cloud, i);
    ++sums.count;
  }

  const std::size_t m = voxels.size();
  PointCloud<S>& out = result.cloud;
  out.points.resize(m);
  result.count.resize(m);
  if (with_intensity) out.intensities.resize(m);
  if (with_time) out.times.resize(m);
  for (std::size_t v = 0; v < m; ++v) {
    const detail::VoxelSums& sums = voxels.at_position(v).value;
    const double count = static_cast<double>(sums.count);
    out.points[v] = (sums.point / count).template cast<S>();
    if (with_intensity) out.intensities[v] = static_cast<S>(sums.intensity / count);
    if (with_time) out.times[v] = sums.time / count;
    result.count[v] = sums.count;
  }
  return result;
}

}  // namespace ulc
