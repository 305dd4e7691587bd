// Fixed-size Eigen aliases used across ULC, templated on the scalar.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ulc {

template <typename S>
using Vec3 = Eigen::Matrix<S, 3, 1>;
template <typename S>
using Vec6 = Eigen::Matrix<S, 6, 1>;
template <typename S>
using Mat3 = Eigen::Matrix<S, 3, 3>;
template <typename S>
using Mat6 = Eigen::Matrix<S, 6, 6>;
/// A rigid transform. ULC names them T_to_from: p_to = T_to_from * p_from.
template <typename S>
using Isometry3 = Eigen::Transform<S, 3, Eigen::Isometry>;

using Vec3d = Vec3<double>;
using Vec6d = Vec6<double>;
using Mat3d = Mat3<double>;
using Mat6d = Mat6<double>;
using Isometry3d = Isometry3<double>;

}  // namespace ulc
