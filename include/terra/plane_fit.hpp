// The largest plane of a scan, by RANSAC with a seeded generator and a least-squares refit:
// what the scancontext* baseline (scan_context.hpp) uses to level a scan; and the few largest
// planes in turn, what the motion frame (pipeline/motion_frame.hpp) picks the ground from.
//
// Conventions this header owns:
//   - The plane is n . p + offset = 0 with |n| = 1, oriented so the sensor (the origin) is on
//     its positive side: offset > 0. For the ground under a LiDAR, n points up.
//   - Points closer than min_range or farther than max_range, or not finite, are not used. At
//     most max_points of the rest (every k-th, in cloud order) enter RANSAC, so the cost does
//     not grow with the cloud.
//   - Deterministic for a seed: SplitMix64 draws, ties between hypotheses keep the first.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <vector>

#include "terra/random_rotation.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace terra {

struct PlaneFitOptions {
  double inlier_distance = 0.15;  ///< metres from the plane
  std::size_t iterations = 300;
  std::size_t max_points = 20000;
  double min_range = 0.5;
  double max_range = 80.0;
  std::uint64_t seed = 1;
};

struct PlaneFit {
  bool ok = false;
  ulc::Vec3d normal = ulc::Vec3d::UnitZ();
  double offset = 0.0;
  std::size_t inliers = 0;  ///< among the points RANSAC used
  std::size_t used = 0;     ///< points RANSAC used
};

namespace plane_detail {

/// The cloud's finite points within [min_range, max_range], every k-th so that at most
/// max_points remain.
template <class Cloud>
std::vector<ulc::Vec3d> usable_points(const Cloud& cloud, const PlaneFitOptions& options) {
  std::vector<ulc::Vec3d> pts;
  const std::size_t n = ulc::traits::size(cloud);
  for (std::size_t i = 0; i < n; ++i) {
    const ulc::Vec3d p = ulc::traits::point(cloud, i).template cast<double>();
    const double r = p.norm();
    if (std::isfinite(r) && r >= options.min_range && r <= options.max_range) pts.push_back(p);
  }
  if (pts.size() > options.max_points && options.max_points > 0) {
    const std::size_t step = (pts.size() + options.max_points - 1) / options.max_points;
    std::size_t out = 0;
    for (std::size_t i = 0; i < pts.size(); i += step) pts[out++] = pts[i];
    pts.resize(out);
  }
  return pts;
}

inline bool is_inlier(const ulc::Vec3d& p, const ulc::Vec3d& normal, double offset,
                      const PlaneFitOptions& options) {
  return std::fabs(normal.dot(p) + offset) <= options.inlier_distance;
}

inline std::size_t count_inliers(const std::vector<ulc::Vec3d>& pts, const ulc::Vec3d& normal,
                                 double offset, const PlaneFitOptions& options) {
  std::size_t c = 0;
  for (const auto& p : pts) c += is_inlier(p, normal, offset, options);
  return c;
}

/// The RANSAC hypothesis with the most inliers (normal, offset, count; count < 3: none).
inline std::tuple<ulc::Vec3d, double, std::size_t> ransac(const std::vector<ulc::Vec3d>& pts,
                                                          const PlaneFitOptions& options) {
  SplitMix64 rng(options.seed);
  auto pick = [&] { return static_cast<std::size_t>(rng.next() % pts.size()); };
  ulc::Vec3d best_n = ulc::Vec3d::UnitZ();
  double best_d = 0.0;
  std::size_t best = 0;
  for (std::size_t it = 0; it < options.iterations; ++it) {
    const ulc::Vec3d& a = pts[pick()];
    const ulc::Vec3d& b = pts[pick()];
    const ulc::Vec3d& c = pts[pick()];
    const ulc::Vec3d cross = (b - a).cross(c - a);
    const double norm = cross.norm();
    if (!(norm > 1e-9)) continue;  // repeated or collinear sample
    const ulc::Vec3d normal = cross / norm;
    const double offset = -normal.dot(a);
    const std::size_t inliers = count_inliers(pts, normal, offset, options);
    if (inliers > best) std::tie(best_n, best_d, best) = std::make_tuple(normal, offset, inliers);
  }
  return {best_n, best_d, best};
}

/// The largest plane of `pts` (RANSAC, then a least-squares refit on its inliers).
inline PlaneFit fit_largest(const std::vector<ulc::Vec3d>& pts, const PlaneFitOptions& options) {
  PlaneFit fit;
  fit.used = pts.size();
  if (pts.size() < 3) return fit;
  const auto [best_n, best_d, best] = ransac(pts, options);
  if (best < 3) return fit;
  // Least-squares refit on the inliers (smallest principal direction), then recount.
  ulc::Vec3d mean = ulc::Vec3d::Zero();
  std::size_t m = 0;
  for (const auto& p : pts)
    if (is_inlier(p, best_n, best_d, options)) mean += p, ++m;
  mean /= static_cast<double>(m);
  ulc::Mat3d cov = ulc::Mat3d::Zero();
  for (const auto& p : pts)
    if (is_inlier(p, best_n, best_d, options)) cov += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<ulc::Mat3d> eig(cov);
  ulc::Vec3d normal = eig.eigenvectors().col(0).normalized();
  double offset = -normal.dot(mean);
  if (offset < 0) {  // the sensor on the positive side
    normal = -normal;
    offset = -offset;
  }
  fit.ok = true;
  fit.normal = normal;
  fit.offset = offset;
  fit.inliers = count_inliers(pts, normal, offset, options);
  return fit;
}

}  // namespace plane_detail

template <class Cloud>
PlaneFit largest_plane(const Cloud& cloud, const PlaneFitOptions& options = {}) {
  return plane_detail::fit_largest(plane_detail::usable_points(cloud, options), options);
}

/// Up to `count` planes, largest first: each the largest plane of the points the ones before it
/// did not take (their inliers removed). Each plane's `used` counts the points left for it.
/// Stops early when a plane cannot be fitted or keeps fewer than `min_inliers` points.
template <class Cloud>
std::vector<PlaneFit> largest_planes(const Cloud& cloud, std::size_t count, std::size_t min_inliers,
                                     const PlaneFitOptions& options = {}) {
  std::vector<PlaneFit> planes;
  std::vector<ulc::Vec3d> pts = plane_detail::usable_points(cloud, options);
  while (planes.size() < count) {
    const PlaneFit fit = plane_detail::fit_largest(pts, options);
    if (!fit.ok || fit.inliers < std::max<std::size_t>(3, min_inliers)) break;
    planes.push_back(fit);
    pts.erase(std::remove_if(pts.begin(), pts.end(),
                             [&](const ulc::Vec3d& p) {
                               return plane_detail::is_inlier(p, fit.normal, fit.offset, options);
                             }),
              pts.end());
  }
  return planes;
}

}  // namespace terra
