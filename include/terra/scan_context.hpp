// scancontext*: the paper's strongest baseline for rotation initialisation, written for the
// benchmark (Sec. "Rotation Initialization" experiments): level each scan on its largest plane
// (taken to be the ground) to fix roll and pitch, then find the yaw with a Scan Context
// descriptor by column shift.
//
// Conventions this header owns:
//   - Levelling: L maps the plane normal (pointing to the sensor's side, plane_fit.hpp) onto +z
//     by the smallest rotation. Levelled points are L p.
//   - Scan Context: rings x sectors bins (20 x 60 as in Scan Context) over range 0..max_range in
//     the levelled x-y plane and azimuth atan2(y, x) from -180 deg; each bin holds the largest
//     height above the fitted plane (levelled z + offset) of its points, 0 when empty. Heights
//     above the plane rather than the sensor make two LiDARs at different heights comparable.
//   - Shift s compares base column c with target column c - s (mod sectors): a target point at
//     azimuth a shows at a + s * 360 / sectors in the base. Distance: Scan Context's mean over
//     columns non-empty in both of 1 - cosine similarity. The best shift is refined by a
//     parabola through its neighbours' distances (sub-sector yaw).
//   - Result: R_base_target = L_base^T Rz(yaw) L_target (p_base ~ R p_target).
//   - Fails (ok = false, reason) when a scan has no plane or the descriptors share no column.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "terra/plane_fit.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace terra {

struct ScanContextOptions {
  std::size_t rings = 20;
  std::size_t sectors = 60;
  double max_range = 80.0;
  PlaneFitOptions plane;
};

struct ScanContext {
  std::size_t rings = 0, sectors = 0;
  std::vector<double> height;  ///< rings x sectors, row-major; 0 = empty bin
  double at(std::size_t ring, std::size_t sector) const { return height[ring * sectors + sector]; }
};

struct ScanContextResult {
  bool ok = false;
  std::string reason;
  ulc::Mat3d rotation = ulc::Mat3d::Identity();  ///< R_base_target
  double yaw_rad = 0.0;
  double distance = std::numeric_limits<double>::infinity();
  PlaneFit base_plane, target_plane;
};

/// The smallest rotation taking unit vector n onto +z.
inline ulc::Mat3d levelling_rotation(const ulc::Vec3d& n) {
  return Eigen::Quaterniond::FromTwoVectors(n, ulc::Vec3d::UnitZ()).toRotationMatrix();
}

/// Scan Context of `cloud` levelled by `plane`.
template <class Cloud>
ScanContext make_scan_context(const Cloud& cloud, const PlaneFit& plane,
                              const ScanContextOptions& options) {
  ScanContext sc;
  sc.rings = options.rings;
  sc.sectors = options.sectors;
  sc.height.assign(sc.rings * sc.sectors, 0.0);
  const ulc::Mat3d L = levelling_rotation(plane.normal);
  for (std::size_t i = 0; i < ulc::traits::size(cloud); ++i) {
    const ulc::Vec3d p = L * ulc::traits::point(cloud, i).template cast<double>();
    if (!std::isfinite(p.squaredNorm()) || p.norm() < options.plane.min_range) continue;
    const double r = std::hypot(p.x(), p.y());
    if (!(r < options.max_range)) continue;
    const auto ring = static_cast<std::size_t>(r / options.max_range * double(sc.rings));
    const double azimuth = std::atan2(p.y(), p.x()) + ulc::kPi;  // [0, 2 pi]
    auto sector = static_cast<std::size_t>(azimuth / (2.0 * ulc::kPi) * double(sc.sectors));
    if (sector >= sc.sectors) sector = 0;
    const double h = p.z() + plane.offset;  // height above the plane
    double& bin = sc.height[std::min(ring, sc.rings - 1) * sc.sectors + sector];
    if (h > bin) bin = h;
  }
  return sc;
}

/// Scan Context distance between base and target shifted by `shift` columns; NaN when no
/// column is non-empty in both.
inline double scan_context_distance(const ScanContext& base, const ScanContext& target,
                                    std::size_t shift) {
  double sum = 0.0;
  std::size_t columns = 0;
  for (std::size_t c = 0; c < base.sectors; ++c) {
    const std::size_t t = (c + base.sectors - shift % base.sectors) % base.sectors;
    double dot = 0, nb = 0, nt = 0;
    for (std::size_t r = 0; r < base.rings; ++r) {
      const double a = base.at(r, c), b = target.at(r, t);
      dot += a * b;
      nb += a * a;
      nt += b * b;
    }
    if (nb > 0 && nt > 0) {
      sum += 1.0 - dot / std::sqrt(nb * nt);
      ++columns;
    }
  }
  return columns ? sum / double(columns) : std::numeric_limits<double>::quiet_NaN();
}

template <class BaseCloud, class TargetCloud>
ScanContextResult scan_context_rotation(const BaseCloud& base, const TargetCloud& target,
                                        const ScanContextOptions& options = {}) {
  ScanContextResult result;
  if (options.rings == 0 || options.sectors < 3 || !(options.max_range > 0)) {
    result.reason = "scan context needs rings >= 1, sectors >= 3 and max_range > 0";
    return result;
  }
  result.base_plane = largest_plane(base, options.plane);
  result.target_plane = largest_plane(target, options.plane);
  if (!result.base_plane.ok || !result.target_plane.ok) {
    result.reason = std::string("no plane found in the ") +
                    (result.base_plane.ok ? "target" : "base") + " scan";
    return result;
  }
  const ScanContext a = make_scan_context(base, result.base_plane, options);
  const ScanContext b = make_scan_context(target, result.target_plane, options);
  std::vector<double> d(options.sectors);
  std::size_t best = options.sectors;
  for (std::size_t s = 0; s < options.sectors; ++s) {
    d[s] = scan_context_distance(a, b, s);
    if (!std::isnan(d[s]) && (best == options.sectors || d[s] < d[best])) best = s;
  }
  if (best == options.sectors) {
    result.reason = "the two scan contexts share no non-empty column";
    return result;
  }
  // Parabola through the best shift and its neighbours: the vertex offset in (-0.5, 0.5).
  const double lo = d[(best + options.sectors - 1) % options.sectors];
  const double hi = d[(best + 1) % options.sectors];
  double frac = 0.0;
  const double curvature = lo - 2.0 * d[best] + hi;
  if (std::isfinite(lo) && std::isfinite(hi) && curvature > 0)
    frac = std::max(-0.5, std::min(0.5, 0.5 * (lo - hi) / curvature));
  result.yaw_rad = (static_cast<double>(best) + frac) * 2.0 * ulc::kPi / double(options.sectors);
  const ulc::Mat3d Rz = ulc::rotation_from_rpy(0.0, 0.0, result.yaw_rad);
  result.rotation = levelling_rotation(result.base_plane.normal).transpose() * Rz *
                    levelling_rotation(result.target_plane.normal);
  result.distance = d[best];
  result.ok = true;
  return result;
}

}  // namespace terra
