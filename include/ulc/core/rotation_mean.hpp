// Averages of rotations: the chordal mean (closed form) and the Karcher (geodesic) mean.
//
// Both take std::vector<Mat3<S>> and optional non-negative weights (one per rotation, positive
// sum). The chordal mean is the rotation nearest, in the Frobenius norm, to the weighted
// arithmetic mean of the matrices. The Karcher mean minimises the weighted sum of squared
// geodesic distances; it starts from the chordal mean and iterates
//   R <- R exp(sum_i w_i log(R^T R_i) / sum_i w_i)
// (a right-side step, in R's own frame) until the step is below the tolerance. At the result
// the weighted logs sum to ~0. It is unique and the iteration converges when the rotations lie
// within a ball of radius pi/2; for wider spreads `converged` may stay false.
// Sums accumulate in double. Nothing here throws, allocates beyond the caller's vectors, or prints.
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

template <typename S>
struct RotationMean {
  Mat3<S> rotation = Mat3<S>::Identity();
  bool ok = false;          ///< false: no rotations or unusable weights; see reason
  const char* reason = "";  ///< empty when ok
  int iterations = 0;       ///< Karcher steps taken (0 for the chordal mean)
  bool converged = false;   ///< Karcher: the last step was below the tolerance; chordal: == ok
};

namespace rotation_mean_detail {

/// Checks the inputs; returns nullptr when usable, else the reason.
template <typename S>
const char* check_inputs(const std::vector<Mat3<S>>& rotations, const std::vector<S>& weights,
                         bool weighted) {
  if (rotations.empty()) return "no rotations to average";
  if (!weighted) return nullptr;
  if (weights.size() != rotations.size()) return "need exactly one weight per rotation";
  double sum = 0;
  for (const S w : weights) {
    if (!(w >= S(0)) || !std::isfinite(static_cast<double>(w)))
      return "weights must be finite and non-negative";
    sum += static_cast<double>(w);
  }
  if (!(sum > 0)) return "weights must have a positive sum";
  return nullptr;
}

template <typename S>
double weight_at(const std::vector<S>& weights, bool weighted, std::size_t i) {
  return weighted ? static_cast<double>(weights[i]) : 1.0;
}

template <typename S>
RotationMean<S> chordal(const std::vector<Mat3<S>>& rotations, const std::vector<S>& weights,
                        bool weighted) {
  RotationMean<S> out;
  if (const char* why = check_inputs(rotations, weights, weighted)) {
    out.reason = why;
    return out;
  }
  // The scale of the sum does not change its nearest rotation: no division needed.
  Mat3d sum = Mat3d::Zero();
  for (std::size_t i = 0; i < rotations.size(); ++i)
    sum += weight_at(weights, weighted, i) * rotations[i].template cast<double>();
  out.rotation = nearest_rotation(sum).template cast<S>();
  out.ok = true;
  out.converged = true;
  return out;
}

template <typename S>
RotationMean<S> karcher(const std::vector<Mat3<S>>& rotations, const std::vector<S>& weights,
                        bool weighted, int max_iterations, S tolerance) {
  RotationMean<S> out = chordal(rotations, weights, weighted);
  out.converged = false;
  if (!out.ok) return out;
  double weight_sum = 0;
  for (std::size_t i = 0; i < rotations.size(); ++i) weight_sum += weight_at(weights, weighted, i);

  Mat3<S> R = out.rotation;
  for (int it = 0; it < max_iterations; ++it) {
    Vec3d step = Vec3d::Zero();
    for (std::size_t i = 0; i < rotations.size(); ++i)
      step += weight_at(weights, weighted, i) *
              so3_log(Mat3<S>(R.transpose() * rotations[i])).template cast<double>();
    step /= weight_sum;
    R = R * so3_exp(step.template cast<S>());
    out.iterations = it + 1;
    if (step.norm() < static_cast<double>(tolerance)) {
      out.converged = true;
      break;
    }
  }
  out.rotation = R;
  return out;
}

template <typename S>
constexpr S default_karcher_tolerance() {
  return S(64) * std::numeric_limits<S>::epsilon();
}

}  // namespace rotation_mean_detail

/// Nearest rotation to the arithmetic mean of the matrices.
template <typename S>
RotationMean<S> chordal_mean(const std::vector<Mat3<S>>& rotations) {
  return rotation_mean_detail::chordal(rotations, std::vector<S>{}, false);
}

/// Nearest rotation to the weighted arithmetic mean of the matrices.
template <typename S>
RotationMean<S> chordal_mean(const std::vector<Mat3<S>>& rotations, const std::vector<S>& weights) {
  return rotation_mean_detail::chordal(rotations, weights, true);
}

/// Geodesic mean; stops when the step's angle (radians) is below `tolerance`.
template <typename S>
RotationMean<S> karcher_mean(
    const std::vector<Mat3<S>>& rotations, int max_iterations = 100,
    lie_detail::non_deduced_t<S> tolerance = rotation_mean_detail::default_karcher_tolerance<S>()) {
  return rotation_mean_detail::karcher(rotations, std::vector<S>{}, false, max_iterations,
                                       tolerance);
}

/// Weighted geodesic mean; stops when the step's angle (radians) is below `tolerance`.
template <typename S>
RotationMean<S> karcher_mean(
    const std::vector<Mat3<S>>& rotations, const std::vector<S>& weights, int max_iterations = 100,
    lie_detail::non_deduced_t<S> tolerance = rotation_mean_detail::default_karcher_tolerance<S>()) {
  return rotation_mean_detail::karcher(rotations, weights, true, max_iterations, tolerance);
}

}  // namespace ulc
