// Synthetic maps for JEEP's unit tests: rectangles of points on planes.
#pragma once

#include <random>
#include <vector>

#include "ulc/core/types.hpp"

namespace jeep_test {

using SurfacePoints = std::vector<ulc::Vec3<double>>;

/// The axes the rectangles are laid along.
inline const ulc::Vec3d kX = ulc::Vec3d::UnitX(), kY = ulc::Vec3d::UnitY(),
                        kZ = ulc::Vec3d::UnitZ();

/// Samples the rectangle origin + u * [0, lu] + v * [0, lv] every `step`, starting at `phase`
/// (two maps of one surface get different points), with 1 cm of noise along its normal.
inline void add_rectangle(SurfacePoints& out, const ulc::Vec3d& origin, const ulc::Vec3d& u,
                          double lu, const ulc::Vec3d& v, double lv, double step, double phase,
                          std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, 0.01);
  const ulc::Vec3d n = u.cross(v).normalized();
  for (double a = phase; a < lu; a += step)
    for (double b = phase; b < lv; b += step)
      out.push_back(origin + a * u + b * v + noise(rng) * n);
}

}  // namespace jeep_test
