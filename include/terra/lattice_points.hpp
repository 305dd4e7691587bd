// The Fibonacci lattice of the paper (Algorithm 1, alg:fibonacci) and the one definition of
// "nearest lattice point" every lookup must reproduce.
//
// Conventions this header owns:
//   - Lattice point i (0 <= i < N, N >= 2) is, exactly as Algorithm 1 writes it,
//       y = 1 - 2 i / (N - 1),  r = sqrt(1 - y^2),  theta = 2 pi i / phi,
//       x = r cos(theta),       z = r sin(theta),   phi = (sqrt(5) + 1) / 2,
//     computed in double. Point 0 is the +y pole, point N-1 the -y pole.
//   - nearest(q) for a unit direction q is the index i minimising squared_distance(q, l_i)
//     (ulc::squared_distance, in double), ties broken by the smaller index. Every lookup
//     (brute force, cube map, kd-tree) returns exactly this index; the tests check it.
//   - Indices are std::uint32_t: a descriptor of 4 billion cells is far beyond any use.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "ulc/core/angles.hpp"
#include "ulc/core/kdtree.hpp"
#include "ulc/core/types.hpp"

namespace terra {

using LatticeIndex = std::uint32_t;

/// Algorithm 1 (alg:fibonacci). Returns no points for n < 2 (y divides by n - 1).
inline std::vector<ulc::Vec3d> fibonacci_lattice(std::size_t n) {
  std::vector<ulc::Vec3d> points;
  if (n < 2) return points;
  const double golden = (std::sqrt(5.0) + 1.0) / 2.0;
  points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double fi = static_cast<double>(i);
    const double y = 1.0 - 2.0 * fi / static_cast<double>(n - 1);
    const double radius = std::sqrt(std::fmax(0.0, 1.0 - y * y));
    const double theta = 2.0 * ulc::kPi * fi / golden;
    points.emplace_back(radius * std::cos(theta), y, radius * std::sin(theta));
  }
  return points;
}

/// The mean spacing of n points spread evenly on the unit sphere: the side of a square of
/// area 4 pi / n, in radians. Used to size lookup tables and search grids.
inline double lattice_spacing_rad(std::size_t n) {
  return n == 0 ? 0.0 : std::sqrt(4.0 * ulc::kPi / static_cast<double>(n));
}

/// The reference answer: O(N) scan. For tests and table construction only.
inline LatticeIndex brute_force_nearest(const std::vector<ulc::Vec3d>& points,
                                        const ulc::Vec3d& q) {
  LatticeIndex best = 0;
  double best_d = ulc::squared_distance(q, points.empty() ? q : points[0]);
  for (std::size_t i = 1; i < points.size(); ++i) {
    const double d = ulc::squared_distance(q, points[i]);
    if (d < best_d) {  // strict: an equal distance keeps the smaller index
      best_d = d;
      best = static_cast<LatticeIndex>(i);
    }
  }
  return best;
}

}  // namespace terra
