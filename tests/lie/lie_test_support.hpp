// Shared helpers for the Lie-group tests: seeded random inputs, per-scalar tolerances and
// matrix distances.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <random>

#include "ulc/core/lie.hpp"

namespace lie_test {

constexpr double kPi = 3.14159265358979323846;

/// Tolerances that scale with the scalar's precision.
template <typename S>
struct Tol;
template <>
struct Tol<float> {
  static constexpr double log = 2e-5;      // exp/log round trips, |phi| error in radians
  static constexpr double fd_step = 1e-2;  // central finite differences
  static constexpr double fd = 1e-3;
  static constexpr double exact = 2e-6;  // algebraic identities on O(1) entries
};
template <>
struct Tol<double> {
  static constexpr double log = 1e-12;
  static constexpr double fd_step = 1e-5;
  static constexpr double fd = 1e-8;
  static constexpr double exact = 1e-13;
};

/// The more precise type a scalar's results are checked against.
template <typename S>
struct Reference;
template <>
struct Reference<float> {
  using type = double;
};
template <>
struct Reference<double> {
  using type = long double;
};

/// Largest absolute entry difference, in double.
template <typename DA, typename DB>
double max_diff(const Eigen::MatrixBase<DA>& a, const Eigen::MatrixBase<DB>& b) {
  return (a.template cast<double>() - b.template cast<double>()).cwiseAbs().maxCoeff();
}

/// Uniformly distributed unit vector (double, cast by the caller).
inline Eigen::Vector3d random_axis(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(n(rng), n(rng), n(rng));
  } while (v.norm() < 1e-3);
  return v.normalized();
}

inline double uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

inline Eigen::Vector3d random_vector(std::mt19937& rng, double scale) {
  return Eigen::Vector3d(uniform(rng, -scale, scale), uniform(rng, -scale, scale),
                         uniform(rng, -scale, scale));
}

/// A random rotation (angle uniform in [0, pi)) in double.
inline Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  return ulc::so3_exp(random_axis(rng) * uniform(rng, 0.0, kPi));
}

template <typename S>
ulc::Isometry3<S> make_isometry(const ulc::Mat3<S>& R, const ulc::Vec3<S>& t) {
  ulc::Isometry3<S> T = ulc::Isometry3<S>::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

template <typename S>
ulc::Isometry3<S> random_isometry(std::mt19937& rng, double translation_scale = 2.0) {
  return make_isometry<S>(random_rotation(rng).cast<S>(),
                          random_vector(rng, translation_scale).cast<S>());
}

}  // namespace lie_test
