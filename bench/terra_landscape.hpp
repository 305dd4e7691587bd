// bench_terra --landscape: the paper's figure of rotations and their distances, in numbers. Over
// a grid of rotations (Euler angles R = Rz(yaw) Ry(pitch) Rx(roll), every `step` degrees) it
// evaluates three distances between the base frame's descriptor F1 and the target's turned by the
// rotation, G = rotate(F2, R):
//   - eq:feature_dis, the paper's (masked by eq:mask, divided by the mask count to the alpha);
//   - the same with ULC's overlap rule (terra/search_params.hpp, min_overlap_ratio): rotations
//     whose mask holds fewer than that share of the grid's largest mask count score +inf;
//   - the plain Euclidean distance ||F1 - G||_2 over every cell (the paper's "ED").
// Per frame pair: where each distance's grid minimum lies from the truth (deg), and the rank of
// the ground truth's own distance among the grid's: 1 when no grid rotation scores better than
// the truth (the truth is the global optimum, as far as the grid can tell). With a picture folder,
// the first pair of each scenario is drawn: the distance over yaw (x) and pitch (y) at the grid
// roll nearest the truth's, coloured by rank among the slice's scoring rotations (dark = small
// distance, white = no overlap), the truth's cell marked in red.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "support/png_canvas.hpp"
#include "terra/terra.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/pose_error.hpp"

namespace terra_landscape {

constexpr double kDeg = ulc::kRadPerDeg;

/// The grid: yaw and roll in [-180, 180), pitch in [-90, 90], every `step` degrees.
struct Grid {
  std::vector<double> yaw, pitch, roll;  ///< degrees
  explicit Grid(double step) {
    for (double a = -180.0; a < 180.0 - 1e-9; a += step) yaw.push_back(a), roll.push_back(a);
    for (double a = -90.0; a <= 90.0 + 1e-9; a += step) pitch.push_back(a);
  }
  std::size_t size() const { return yaw.size() * pitch.size() * roll.size(); }
  /// Index (yaw i, pitch j, roll k) -> flat.
  std::size_t at(std::size_t i, std::size_t j, std::size_t k) const {
    return (i * pitch.size() + j) * roll.size() + k;
  }
  ulc::Mat3d rotation(std::size_t flat) const {
    const std::size_t k = flat % roll.size(), j = (flat / roll.size()) % pitch.size(),
                      i = flat / (roll.size() * pitch.size());
    return (Eigen::AngleAxisd(yaw[i] * kDeg, ulc::Vec3d::UnitZ()) *
            Eigen::AngleAxisd(pitch[j] * kDeg, ulc::Vec3d::UnitY()) *
            Eigen::AngleAxisd(roll[k] * kDeg, ulc::Vec3d::UnitX()))
        .toRotationMatrix();
  }
};

/// Both distances at every grid rotation (eq:feature_dis: +inf without overlap), and at the
/// ground truth.
struct Landscape {
  std::vector<double> feature, euclidean;
  std::vector<std::size_t> mask;  ///< eq:mask counts of `feature`
  double truth_feature = 0.0, truth_euclidean = 0.0;
  std::size_t truth_mask = 0;
};

/// eq:feature_dis with the overlap rule: +inf where the mask holds fewer than `ratio` of the
/// largest count; the truth's value likewise (returned in `at_truth`).
inline std::vector<double> with_overlap_rule(const Landscape& l, double ratio, double& at_truth) {
  const std::size_t largest = *std::max_element(l.mask.begin(), l.mask.end());
  const double floor = ratio * static_cast<double>(largest);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> out(l.feature.size());
  for (std::size_t r = 0; r < out.size(); ++r)
    out[r] = static_cast<double>(l.mask[r]) < floor ? inf : l.feature[r];
  at_truth = static_cast<double>(l.truth_mask) < floor ? inf : l.truth_feature;
  return out;
}

template <typename S>
double euclidean_distance(const terra::Descriptor<S>& f1, const terra::Descriptor<S>& g) {
  double sum = 0.0;
  for (std::size_t j = 0; j < f1.size(); ++j) {
    const double d = static_cast<double>(f1.range[j]) - static_cast<double>(g.range[j]);
    sum += d * d;
  }
  return std::sqrt(sum);
}

template <typename S>
Landscape evaluate(const terra::Lattice& lattice, const terra::Descriptor<S>& f1,
                   const terra::Descriptor<S>& f2, const terra::DistanceParams& params,
                   const Grid& grid, const ulc::Mat3d& truth) {
  Landscape out;
  const terra::Descriptor<S> at_truth = terra::rotate(lattice, f2, truth);
  const terra::DistanceValue truth_value = terra::descriptor_distance(f1, at_truth, params);
  out.truth_feature = truth_value.distance;
  out.truth_mask = truth_value.mask_count;
  out.truth_euclidean = euclidean_distance(f1, at_truth);
  out.feature.resize(grid.size());
  out.euclidean.resize(grid.size());
  out.mask.resize(grid.size());
  for (std::size_t r = 0; r < grid.size(); ++r) {
    const terra::Descriptor<S> g = terra::rotate(lattice, f2, grid.rotation(r));
    const terra::DistanceValue v = terra::descriptor_distance(f1, g, params);
    out.feature[r] = v.distance;
    out.mask[r] = v.mask_count;
    out.euclidean[r] = euclidean_distance(f1, g);
  }
  return out;
}

/// The grid rotation nearest `truth` and its angle from it (deg).
inline std::size_t nearest_cell(const Grid& grid, const ulc::Mat3d& truth, double& angle_deg) {
  std::size_t best = 0;
  angle_deg = std::numeric_limits<double>::infinity();
  for (std::size_t r = 0; r < grid.size(); ++r) {
    const double a = ulc::rotation_error_rad(truth, grid.rotation(r)) / kDeg;
    if (a < angle_deg) angle_deg = a, best = r;
  }
  return best;
}

/// What one distance says about one frame pair.
struct Verdict {
  double minimum_error_deg = 180.0;  ///< the grid minimum's angle from the truth
  std::size_t truth_rank = 0;        ///< 1 + grid rotations scoring strictly below the truth
};

inline Verdict judge(const Grid& grid, const std::vector<double>& d, double at_truth,
                     const ulc::Mat3d& truth) {
  Verdict v;
  const auto minimum = std::min_element(d.begin(), d.end()) - d.begin();
  if (std::isfinite(d[static_cast<std::size_t>(minimum)]))
    v.minimum_error_deg =
        ulc::rotation_error_rad(truth, grid.rotation(static_cast<std::size_t>(minimum))) / kDeg;
  v.truth_rank = 1 + static_cast<std::size_t>(
                         std::count_if(d.begin(), d.end(), [&](double x) { return x < at_truth; }));
  return v;
}

/// The yaw x pitch slice at the truth cell's roll, coloured by rank among the slice's finite
/// values (dark = small distance; white: no overlap), the truth's cell outlined in red; `cell`
/// pixels per grid step.
inline bool write_slice_png(const std::string& path, const Grid& grid, const std::vector<double>& d,
                            std::size_t truth_cell, int cell = 14) {
  const std::size_t k = truth_cell % grid.roll.size();
  std::vector<double> slice;
  for (std::size_t i = 0; i < grid.yaw.size(); ++i)
    for (std::size_t j = 0; j < grid.pitch.size(); ++j) slice.push_back(d[grid.at(i, j, k)]);
  std::vector<double> sorted;  // the finite values: ranks among the rotations that score
  for (double v : slice)
    if (std::isfinite(v)) sorted.push_back(v);
  std::sort(sorted.begin(), sorted.end());
  const int w = static_cast<int>(grid.yaw.size()) * cell,
            h = static_cast<int>(grid.pitch.size()) * cell;
  ulc_bench::png_canvas::Canvas canvas(w, h);
  for (std::size_t i = 0; i < grid.yaw.size(); ++i)
    for (std::size_t j = 0; j < grid.pitch.size(); ++j) {
      const double v = slice[i * grid.pitch.size() + j];
      const double rank =
          static_cast<double>(std::lower_bound(sorted.begin(), sorted.end(), v) - sorted.begin()) /
          static_cast<double>(sorted.size());
      const auto grey = static_cast<std::uint8_t>(std::isfinite(v) ? 20 + 230 * rank : 255);
      const int x = static_cast<int>(i) * cell,
                y = h - (static_cast<int>(j) + 1) * cell;  // pitch grows upwards
      canvas.rect(x, y, x + cell, y + cell, {grey, grey, grey});
    }
  const std::size_t ti = truth_cell / (grid.roll.size() * grid.pitch.size());
  const std::size_t tj = (truth_cell / grid.roll.size()) % grid.pitch.size();
  const int x = static_cast<int>(ti) * cell, y = h - (static_cast<int>(tj) + 1) * cell;
  const ulc_bench::png_canvas::Rgb red = {220, 30, 30};
  canvas.line(x, y, x + cell, y, red, 2);
  canvas.line(x, y + cell, x + cell, y + cell, red, 2);
  canvas.line(x, y, x, y + cell, red, 2);
  canvas.line(x + cell, y, x + cell, y + cell, red, 2);
  return canvas.write_png(path);
}

}  // namespace terra_landscape
