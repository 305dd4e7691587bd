// A dense grid of one byte per voxel over a square of 2 * half_extent metres about the origin and
// the heights [min_height, max_height). The ground vote (ground_vote.hpp) marks occupied voxels of
// levelled points (x, y about the sensor, z the height above its ground); the free-space check
// (pipeline/free_space.hpp) keeps a state per voxel of a cube about the base. Built once, read
// millions of times, so lookups are a bounds check and an index.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "ulc/core/types.hpp"

namespace terra {

class OccupancyGrid {
 public:
  /// An empty grid; voxel > 0, half_extent > 0, max_height > min_height (the caller's options
  /// are checked before: ground_vote_problem).
  OccupancyGrid(double voxel, double half_extent, double min_height, double max_height)
      : voxel_(voxel), half_(half_extent), zmin_(min_height) {
    nxy_ = static_cast<std::size_t>(std::ceil(2.0 * half_extent / voxel));
    nz_ = static_cast<std::size_t>(std::ceil((max_height - min_height) / voxel));
    cells_.assign(nxy_ * nxy_ * nz_, 0);
  }

  double voxel() const { return voxel_; }

  /// Marks the voxel holding p (ignored outside the grid).
  void mark(const ulc::Vec3d& p) {
    if (std::uint8_t* c = cell(p)) *c = 1;
  }

  bool occupied(const ulc::Vec3d& p) const { return value(p) != 0; }

  /// The byte of the voxel holding p, nullptr outside the grid.
  std::uint8_t* cell(const ulc::Vec3d& p) {
    std::size_t k;
    return index(p, k) ? &cells_[k] : nullptr;
  }

  /// The byte of the voxel holding p; 0 outside the grid.
  std::uint8_t value(const ulc::Vec3d& p) const {
    std::size_t k;
    return index(p, k) ? cells_[k] : 0;
  }

 private:
  bool index(const ulc::Vec3d& p, std::size_t& k) const {
    const double fx = std::floor((p.x() + half_) / voxel_);
    const double fy = std::floor((p.y() + half_) / voxel_);
    const double fz = std::floor((p.z() - zmin_) / voxel_);
    const double nxy = static_cast<double>(nxy_), nz = static_cast<double>(nz_);
    // Compared as doubles before any cast (a far or NaN coordinate fails here).
    if (!(fx >= 0.0 && fy >= 0.0 && fz >= 0.0 && fx < nxy && fy < nxy && fz < nz)) return false;
    const auto ix = static_cast<std::size_t>(fx), iy = static_cast<std::size_t>(fy),
               iz = static_cast<std::size_t>(fz);
    k = (iz * nxy_ + iy) * nxy_ + ix;
    return true;
  }

  double voxel_, half_, zmin_;
  std::size_t nxy_ = 0, nz_ = 0;
  std::vector<std::uint8_t> cells_;
};

}  // namespace terra
