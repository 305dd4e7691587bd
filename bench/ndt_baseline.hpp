// A refinement baseline for the refinement table: point-to-distribution NDT (Biber and Strasser,
// "The normal distributions transform", IROS 2003; in 3D after Magnusson, "The Three-Dimensional
// Normal-Distributions Transform", PhD thesis, Orebro 2009, chapter 6), written for bench_jeep
// only (the library has no NDT; PCL is not a dependency). What it does:
//   - the caller prepares both clouds (bench_jeep: as scan-scan does, odometry::prepare_scan with
//     jeep::ScanScanOptions' scan options: 2-100 m, 0.25 m voxel centroids);
//   - the target's points are binned into cubic cells (ulc/core/voxel.hpp's keys); a cell with at
//     least 5 points gets their mean and sample covariance (1 / (n - 1)), whose eigenvalues below
//     1e-3 of the largest are raised to it (as Magnusson's chapter 6 does: a flat cell's covariance
//     is otherwise near singular); cells with fewer points are empty;
//   - the score of a source point a moved to x = T a against a cell (mean q, covariance S) is
//     d1 exp(-d2 / 2 m), m = (x - q)^T S^-1 (x - q): Magnusson's Gaussian fit to
//     -log(c1 exp(-m / 2) + c2), the negative log-likelihood of a normal-plus-uniform mixture,
//     less its constant d3. c1 = 1 - p_o (the Gaussian's peak, its normalisation dropped as a
//     constant), c2 = p_o / r^3 (outliers spread uniformly over a cell of side r), p_o = 0.55;
//     d3 = -log c2, d1 = -log(c1 + c2) - d3 < 0, d2 = -2 log((-log(c1 exp(-1/2) + c2) - d3) / d1)
//     (the fit agrees with the mixture at m = 0, m = 1 and m -> infinity);
//   - each point scores against the cell it falls in and that cell's six face neighbours (the
//     non-empty ones), so that a point near a cell face still sees the surface continuing in the
//     next cell and the score does not drop to nothing at every face; the objective is the sum
//     over points and their cells, minimised (d1 < 0);
//   - the cells each point scores against are found once per iteration and held within it, like
//     GICP's matches; the gradient and Hessian use this file's own point
//     derivatives for the library's left perturbation instead of the thesis's Euler angles:
//     x(xi) = exp(xi) x ~= x + rho + [phi]x x + 1/2 ([phi]x [phi]x x + [phi]x rho), so
//     dx/dxi = [I, -[x]x] and the second-order term gives the Hessian's w-weighted part
//     (w = S^-1 (x - q)): w^T d2x/dphi2 = 1/2 (w x^T + x w^T) - (w . x) I and
//     w^T d2x/drho dphi = 1/2 [w]x;
//   - one Newton step per iteration, damped as Levenberg-Marquardt (H + lambda diag(|H|)) until
//     the damped Hessian is positive definite and the step lowers the objective over the held
//     cells (the thesis uses a More-Thuente line search instead);
//   - coarse to fine over cell sides 4, 2 and 1 m: 4 m cells reach a 2 m start (scan-scan's first
//     gate is 4 m too), and 1 m is the finest that a 0.25 m-voxel cloud fills (a surface through a
//     1 m cell leaves about 16 centroids in it; through a 0.5 m cell about 4, fewer than the 5 a
//     cell needs);
//   - a stage ends when an update moves T by less than the tolerances or after max_iterations;
//     the result is converged when the last stage ended on a small update with at least
//     min_scored source points scoring against some cell.
// Conventions: the library's (ulc/core/lie.hpp), a left perturbation T <- exp(xi) T with
// xi = [rho; phi]; the pose is T_target_source (p_target = T * p_source). No randomness; the
// per-point terms are computed in parallel but summed in point order: the same input gives the
// same answer on any number of threads.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"
#include "ulc/core/voxel.hpp"

namespace ndt_baseline {

using ulc::Isometry3d;
using ulc::Mat3d;
using ulc::Mat6d;
using ulc::Vec3d;
using ulc::Vec6d;
using Points = std::vector<Vec3d>;

struct Options {
  std::vector<double> resolutions = {4.0, 2.0, 1.0};  ///< m, cell side per stage
  std::size_t min_cell_points = 5;                    ///< fewer: the cell is empty
  double min_eigenvalue_ratio = 1e-3;   ///< of the largest: a cell's smallest allowed eigenvalue
  double outlier_ratio = 0.55;          ///< p_o of the score's mixture
  int max_iterations = 30;              ///< per stage
  double translation_tolerance = 1e-4;  ///< m, an update this small ends a stage
  double rotation_tolerance = 1e-5;     ///< rad
  std::size_t min_scored = 50;  ///< source points with a cell; fewer: the stage (and result) fails
};

struct Result {
  bool converged = false;
  Isometry3d pose = Isometry3d::Identity();  ///< T_target_source
  int iterations = 0;                        ///< over all stages
  std::size_t scored = 0;  ///< source points with at least one cell, in the last iteration
  double score = 0.0;      ///< the objective over the held cells, at the returned pose
};

/// One cell's normal distribution: mean and inverse covariance.
struct Cell {
  Vec3d mean = Vec3d::Zero();
  Mat3d information = Mat3d::Zero();
};

/// The target in cells of one side: the non-empty cells, in the order of their first point.
struct Grid {
  double resolution = 1.0;
  ulc::VoxelMap<Cell> cells;
};

/// The score's constants d1, d2 (Magnusson) for one cell side.
struct ScoreConstants {
  double d1 = -1.0, d2 = 1.0;
};

namespace detail {

/// Up to seven cells (own and face neighbours) per source point, as positions in the grid.
constexpr std::size_t kMaxCells = 7;
constexpr std::size_t kNoCell = std::numeric_limits<std::size_t>::max();
using CellList = std::array<std::size_t, kMaxCells>;

/// Mean and regularised information of one cell's points, or false when they span no volume.
inline bool fit_cell(const Points& points, const std::vector<std::size_t>& members,
                     double min_eigenvalue_ratio, Cell& cell) {
  Vec3d mean = Vec3d::Zero();
  for (std::size_t k : members) mean += points[k];
  mean /= static_cast<double>(members.size());
  Mat3d cov = Mat3d::Zero();
  for (std::size_t k : members)
    cov.noalias() += (points[k] - mean) * (points[k] - mean).transpose();
  cov /= static_cast<double>(members.size() - 1);
  const Eigen::SelfAdjointEigenSolver<Mat3d> eig(cov);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()[2] > 0.0)) return false;
  const double smallest = min_eigenvalue_ratio * eig.eigenvalues()[2];
  const Vec3d inverse = eig.eigenvalues().cwiseMax(smallest).cwiseInverse();
  cell.mean = mean;
  cell.information = eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
  return true;
}

}  // namespace detail

/// The target's cells of side `resolution` (see the header comment). Serial, in point order.
inline Grid build_grid(const Points& target, double resolution, const Options& o = {}) {
  Grid grid;
  grid.resolution = resolution;
  ulc::VoxelMap<std::vector<std::size_t>> members;
  for (std::size_t i = 0; i < target.size(); ++i)
    if (const auto key = ulc::make_voxel_key(target[i], resolution)) members[*key].push_back(i);
  const std::size_t needed = std::max<std::size_t>(o.min_cell_points, 2);
  for (const auto& entry : members) {
    Cell cell;
    if (entry.value.size() >= needed &&
        detail::fit_cell(target, entry.value, o.min_eigenvalue_ratio, cell))
      grid.cells[entry.key] = cell;
  }
  return grid;
}

/// d1, d2 of the Gaussian fitted to -log(c1 exp(-m / 2) + c2) at m = 0, 1 and infinity
/// (Magnusson; c1, c2 as in the header comment).
inline ScoreConstants score_constants(double resolution, double outlier_ratio) {
  const double c1 = 1.0 - outlier_ratio;
  const double c2 = outlier_ratio / (resolution * resolution * resolution);
  const double d3 = -std::log(c2);
  ScoreConstants k;
  k.d1 = -std::log(c1 + c2) - d3;
  k.d2 = -2.0 * std::log((-std::log(c1 * std::exp(-0.5) + c2) - d3) / k.d1);
  return k;
}

namespace detail {

/// The non-empty cells among x's own and its six face neighbours (own first).
inline CellList cells_near(const Grid& grid, const Vec3d& x) {
  CellList out;
  out.fill(kNoCell);
  const auto key = ulc::make_voxel_key(x, grid.resolution);
  if (!key) return out;
  static constexpr std::array<std::array<int, 3>, kMaxCells> kOffsets = {
      {{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};
  std::size_t n = 0;
  for (const auto& d : kOffsets) {
    // int64 first: a key at the int32 limit has no neighbour beyond it.
    const std::int64_t x64 = std::int64_t{key->x} + d[0], y64 = std::int64_t{key->y} + d[1],
                       z64 = std::int64_t{key->z} + d[2];
    constexpr std::int64_t lo = std::numeric_limits<std::int32_t>::min(),
                           hi = std::numeric_limits<std::int32_t>::max();
    if (x64 < lo || x64 > hi || y64 < lo || y64 > hi || z64 < lo || z64 > hi) continue;
    const ulc::VoxelKey k{static_cast<std::int32_t>(x64), static_cast<std::int32_t>(y64),
                          static_cast<std::int32_t>(z64)};
    if (const auto pos = grid.cells.position(k)) out[n++] = *pos;
  }
  return out;
}

/// Each source point's cells at pose T (found per point in parallel; each result is the point's
/// own, so any thread count gives the same lists).
inline std::vector<CellList> associate(const Points& source, const Grid& grid,
                                       const Isometry3d& T) {
  std::vector<CellList> out(source.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, source.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i)
                        out[i] = cells_near(grid, T * source[i]);
                    });
  return out;
}

inline std::size_t count_scored(const std::vector<CellList>& cells) {
  return static_cast<std::size_t>(
      std::count_if(cells.begin(), cells.end(), [](const CellList& c) { return c[0] != kNoCell; }));
}

/// One point's score against its cells: sum of d1 exp(-d2 / 2 m), m the Mahalanobis square.
inline double point_score(const Grid& grid, const CellList& cells, const Vec3d& x,
                          const ScoreConstants& k) {
  double sum = 0.0;
  for (std::size_t c : cells) {
    if (c == kNoCell) break;
    const Cell& cell = grid.cells.at_position(c).value;
    const Vec3d e = x - cell.mean;
    sum += k.d1 * std::exp(-0.5 * k.d2 * e.dot(cell.information * e));
  }
  return sum;
}

/// One point's gradient and Hessian with respect to a left perturbation of T (the derivatives
/// of the header comment), added to g and H.
inline void add_point_derivatives(const Grid& grid, const CellList& cells, const Vec3d& x,
                                  const ScoreConstants& k, Vec6d& g, Mat6d& H) {
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>() = Mat3d::Identity();
  J.rightCols<3>() = -ulc::hat(x);
  for (std::size_t c : cells) {
    if (c == kNoCell) break;
    const Cell& cell = grid.cells.at_position(c).value;
    const Vec3d e = x - cell.mean;
    const Vec3d w = cell.information * e;
    const double weight = -k.d1 * k.d2 * std::exp(-0.5 * k.d2 * e.dot(w));  // > 0
    const Vec6d Jw = J.transpose() * w;
    Mat6d second = Mat6d::Zero();  // w^T d2x / dxi2
    second.bottomRightCorner<3, 3>() =
        0.5 * (w * x.transpose() + x * w.transpose()) - w.dot(x) * Mat3d::Identity();
    second.topRightCorner<3, 3>() = 0.5 * ulc::hat(w);
    second.bottomLeftCorner<3, 3>() = -0.5 * ulc::hat(w);
    g.noalias() += weight * Jw;
    H.noalias() +=
        weight * (J.transpose() * cell.information * J + second - k.d2 * Jw * Jw.transpose());
  }
}

/// Per-point values computed in parallel, then added in point order (thread-count invariant).
template <class Value, class PerPoint>
Value sum_in_order(std::size_t n, const Value& zero, PerPoint&& per_point) {
  std::vector<Value> terms(n, zero);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i)
                        terms[i] = per_point(i);
                    });
  Value sum = zero;
  for (const auto& t : terms) sum += t;
  return sum;
}

}  // namespace detail

/// The objective at T over held cells (the sum over points and cells with d1 < 0: lower is better).
inline double score(const Points& source, const Grid& grid,
                    const std::vector<detail::CellList>& cells, const Isometry3d& T,
                    const ScoreConstants& k) {
  return detail::sum_in_order(source.size(), 0.0, [&](std::size_t i) {
    return detail::point_score(grid, cells[i], T * source[i], k);
  });
}

/// Gradient g and Hessian H of score() at T for a left perturbation exp(xi) T.
inline void derivatives(const Points& source, const Grid& grid,
                        const std::vector<detail::CellList>& cells, const Isometry3d& T,
                        const ScoreConstants& k, Vec6d& g, Mat6d& H) {
  using Terms = Eigen::Matrix<double, 6, 7>;  // column 0: g, columns 1-6: H
  const Terms sum = detail::sum_in_order(source.size(), Terms::Zero().eval(), [&](std::size_t i) {
    Vec6d gi = Vec6d::Zero();
    Mat6d Hi = Mat6d::Zero();
    detail::add_point_derivatives(grid, cells[i], T * source[i], k, gi, Hi);
    Terms t;
    t.col(0) = gi;
    t.rightCols<6>() = Hi;
    return t;
  });
  g = sum.col(0);
  H = sum.rightCols<6>();
}

namespace detail {

/// A step's update and the score at the pose it leaves.
struct Step {
  Vec6d xi;
  double score;
};

/// One damped Newton step over held cells: the damping grows until H + lambda diag(|H|) is
/// positive definite and the step lowers the score (and shrinks after a success). Returns the
/// update taken (zero when no step lowers the score: a minimum for these cells) and the score at
/// the resulting T.
inline Step newton_step(const Points& source, const Grid& grid, const std::vector<CellList>& cells,
                        const ScoreConstants& k, Isometry3d& T, double& lambda) {
  Vec6d g;
  Mat6d H;
  derivatives(source, grid, cells, T, k, g, H);
  const double before = score(source, grid, cells, T, k);
  // diag(H) floored: an indefinite H may have non-positive diagonal entries.
  const Vec6d scale = H.diagonal().cwiseAbs().cwiseMax(1e-12 * H.diagonal().cwiseAbs().maxCoeff() +
                                                       std::numeric_limits<double>::min());
  for (int attempt = 0; attempt < 20; ++attempt) {
    Mat6d damped = H;
    damped.diagonal() += lambda * scale;
    const Eigen::LLT<Mat6d> llt(damped);
    if (llt.info() == Eigen::Success) {
      const Vec6d xi = llt.solve(-g);
      const Isometry3d candidate = ulc::se3_exp(xi) * T;
      const double after = xi.allFinite() ? score(source, grid, cells, candidate, k) : before;
      if (xi.allFinite() && after <= before) {
        T = candidate;
        lambda = std::max(lambda / 10.0, 1e-9);
        return {xi, after};
      }
    }
    lambda *= 10.0;
  }
  return {Vec6d::Zero(), before};
}

/// Iterations of one stage (one grid). True when it ended on a small update; false after
/// max_iterations or with too few source points scoring against a cell.
inline bool run_stage(const Points& source, const Grid& grid, const Options& o, Result& r) {
  const ScoreConstants k = score_constants(grid.resolution, o.outlier_ratio);
  double lambda = 1e-6;
  for (int it = 0; it < o.max_iterations; ++it) {
    const auto cells = associate(source, grid, r.pose);
    r.scored = count_scored(cells);
    if (r.scored < o.min_scored) return false;
    ++r.iterations;
    const auto [xi, score_after] = newton_step(source, grid, cells, k, r.pose, lambda);
    r.score = score_after;
    if (xi.head<3>().norm() < o.translation_tolerance && xi.tail<3>().norm() < o.rotation_tolerance)
      return true;
  }
  return false;
}

}  // namespace detail

/// NDT of `source` onto `target` from `initial` (both clouds prepared by the caller): the pose
/// T_target_source.
inline Result ndt(const Points& source, const Points& target, const Isometry3d& initial,
                  const Options& o = {}) {
  Result r;
  r.pose = initial;
  if (source.size() < o.min_scored || target.empty() || !initial.matrix().allFinite() ||
      o.resolutions.empty())
    return r;
  for (double resolution : o.resolutions)
    r.converged = detail::run_stage(source, build_grid(target, resolution, o), o, r);
  return r;
}

}  // namespace ndt_baseline
