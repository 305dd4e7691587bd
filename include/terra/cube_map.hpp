// Cube-map cells: an O(1) partition of the unit sphere's directions.
//
// Conventions this header owns:
//   - A direction q (finite, non-zero; not necessarily unit) belongs to the face of its largest
//     |component| (ties: x before y before z), sign included: faces 0..5 = +x, -x, +y, -y, +z, -z.
//   - On a face the two other components divided by the major one give (u, v) in [-1, 1]:
//       x faces: (u, v) = (y, z) / |x|,  y faces: (z, x) / |y|,  z faces: (x, y) / |z|.
//   - The face square is split into M x M equal (u, v) cells; u = 1 (or v = 1) belongs to the
//     last cell. cell = (face * M + iv) * M + iu.
//   - A cell's region on the sphere is bounded by four great circles (u = const is the plane
//     through the origin a - u * major = 0), so it is a convex spherical quadrilateral: the
//     farthest point of it from any direction within 90 degrees is one of its four corners.
//     lattice.hpp relies on this to bound which lattice points a cell can be nearest to.
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstddef>

#include "ulc/core/types.hpp"

namespace terra {

class CubeMapGrid {
 public:
  CubeMapGrid() = default;
  explicit CubeMapGrid(std::size_t cells_per_edge)
      : m_(std::max<std::size_t>(cells_per_edge, 1)), half_m_(0.5 * static_cast<double>(m_)) {}

  std::size_t cells_per_edge() const { return m_; }
  std::size_t cell_count() const { return 6 * m_ * m_; }

  /// The cell holding direction q (finite and non-zero). Written without data-dependent
  /// branches (the face is picked by selects, not ifs): queries of the search come in no
  /// predictable face order.
  std::size_t cell_of(const ulc::Vec3d& q) const {
    const double ax = std::fabs(q.x()), ay = std::fabs(q.y()), az = std::fabs(q.z());
    const bool x_major = ax >= ay && ax >= az;
    const bool y_major = !x_major && ay >= az;
    const std::size_t axis = x_major ? 0 : (y_major ? 1 : 2);
    // (u, v) = the next two components in cyclic order: (y, z), (z, x), (x, y).
    const std::size_t next = axis == 2 ? 0 : axis + 1;
    const std::size_t after = next == 2 ? 0 : next + 1;
    const double signed_major = q[static_cast<Eigen::Index>(axis)];
    const double major = std::fabs(signed_major);
    assert(major > 0 && std::isfinite(major));
    const std::size_t face = 2 * axis + (signed_major >= 0 ? 0 : 1);
    const double scale = half_m_ / major;
    const double u = q[static_cast<Eigen::Index>(next)];
    const double v = q[static_cast<Eigen::Index>(after)];
    return (face * m_ + to_cell(v * scale + half_m_)) * m_ + to_cell(u * scale + half_m_);
  }

  /// The (not normalised) direction of face point (u, v).
  static ulc::Vec3d direction(std::size_t face, double u, double v) {
    const double s = (face % 2 == 0) ? 1.0 : -1.0;
    switch (face / 2) {
      case 0:
        return ulc::Vec3d(s, u, v);
      case 1:
        return ulc::Vec3d(v, s, u);
      default:
        return ulc::Vec3d(u, v, s);
    }
  }

  /// Unit direction of the cell's (u, v) centre.
  ulc::Vec3d centre(std::size_t cell) const {
    const auto [face, iu, iv] = split(cell);
    return direction(face, edge(iu) + 1.0 / static_cast<double>(m_),
                     edge(iv) + 1.0 / static_cast<double>(m_))
        .normalized();
  }

  /// Unit directions of the cell's four corners.
  std::array<ulc::Vec3d, 4> corners(std::size_t cell) const {
    const auto [face, iu, iv] = split(cell);
    return {direction(face, edge(iu), edge(iv)).normalized(),
            direction(face, edge(iu + 1), edge(iv)).normalized(),
            direction(face, edge(iu), edge(iv + 1)).normalized(),
            direction(face, edge(iu + 1), edge(iv + 1)).normalized()};
  }

 private:
  struct Split {
    std::size_t face, iu, iv;
  };
  Split split(std::size_t cell) const { return {cell / (m_ * m_), cell % m_, (cell / m_) % m_}; }
  /// u (or v) of the cell edge i: -1 + 2 i / M.
  double edge(std::size_t i) const {
    return -1.0 + 2.0 * static_cast<double>(i) / static_cast<double>(m_);
  }
  std::size_t to_cell(double t) const {
    // t is in [0, M] up to rounding; clamping keeps edge directions in the outermost cells.
    const double clamped = std::min(std::max(t, 0.0), static_cast<double>(m_ - 1));
    return static_cast<std::size_t>(clamped);
  }

  std::size_t m_ = 1;
  double half_m_ = 0.5;
};

/// Angle between two unit vectors, accurate at 0 and pi (atan2 form).
inline double angle_between(const ulc::Vec3d& a, const ulc::Vec3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace terra
