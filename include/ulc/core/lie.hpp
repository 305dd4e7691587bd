// SO(3) and SE(3): hat/vee, exp/log, Jacobians, adjoint, interpolation, roll-pitch-yaw.
//
// Conventions (used everywhere in ULC):
// - Tangent vectors of SE(3) are xi = [rho; phi] (translation part first, then rotation), as in
//   the paper's point Jacobian J_p = [I, -[Tp]x].
// - Perturbations are on the LEFT: T (+) dxi = exp(dxi) * T.
// - For SO(3): phi, left perturbation R (+) dphi = exp(dphi) R.
// - Transforms are ulc::Isometry3<S>; everything is templated on the scalar S (float, double).
// - Left Jacobian J_l(phi):  exp(phi + d) ~= exp(J_l(phi) d) exp(phi).
//   Right Jacobian J_r(phi): exp(phi + d) ~= exp(phi) exp(J_r(phi) d);  J_r(phi) = J_l(-phi).
//   The same two definitions hold for SE(3) with xi in place of phi.
// - so3_log returns |phi| in [0, pi]; at exactly pi either sign of the axis is a valid answer.
// - Roll, pitch, yaw are radians with R = Rz(yaw) Ry(pitch) Rx(roll) (the ROS convention).
//
// Closed forms divide by powers of the angle; below a per-scalar threshold they switch to Taylor
// series (through theta^6), so every function is smooth and accurate down to and at zero.
// Nothing here throws, allocates or prints.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "ulc/core/types.hpp"

namespace ulc {

namespace lie_detail {

template <typename T>
struct type_identity {
  using type = T;
};
/// Keeps a parameter out of template deduction (interpolate(T0, T1, 0.5) with S = float).
template <typename T>
using non_deduced_t = typename type_identity<T>::type;

/// theta^2 below which the Taylor series (through theta^6) replace the closed forms. Chosen so
/// the first dropped term is below the scalar's rounding while the closed forms, which lose
/// digits to cancellation as theta shrinks, are still accurate at the switch.
template <typename S>
constexpr S small_angle_sq() {
  constexpr int digits = std::numeric_limits<S>::digits;
  if constexpr (digits <= 24) {
    return S(1e-1);
  } else if constexpr (digits <= 53) {
    return S(1e-3);
  } else if constexpr (digits <= 64) {
    return S(1e-4);
  } else {
    return S(1e-8);
  }
}

/// The angle-dependent scalars of Rodrigues' formula and the SO(3) Jacobians.
template <typename S>
struct So3Coefficients {
  S a;  ///< sin(theta) / theta
  S b;  ///< (1 - cos(theta)) / theta^2
  S c;  ///< (theta - sin(theta)) / theta^3
};

template <typename S>
So3Coefficients<S> so3_coefficients(S theta_sq) {
  if (theta_sq < small_angle_sq<S>()) {
    const S t2 = theta_sq, t4 = t2 * t2, t6 = t4 * t2;
    return {S(1) - t2 / S(6) + t4 / S(120) - t6 / S(5040),
            S(0.5) - t2 / S(24) + t4 / S(720) - t6 / S(40320),
            S(1) / S(6) - t2 / S(120) + t4 / S(5040) - t6 / S(362880)};
  }
  using std::sin;
  using std::sqrt;
  const S theta = sqrt(theta_sq);
  const S sin_theta = sin(theta);
  const S sin_half = sin(theta / S(2));
  // 1 - cos = 2 sin^2(theta/2) avoids the cancellation of 1 - cos for small theta.
  return {sin_theta / theta, S(2) * sin_half * sin_half / theta_sq,
          (theta - sin_theta) / (theta_sq * theta)};
}

/// 1/theta^2 - cot(theta/2) / (2 theta): the K^2 coefficient of the inverse SO(3) Jacobians.
/// Finite for theta < 2 pi.
template <typename S>
S so3_inverse_jacobian_coefficient(S theta_sq) {
  if (theta_sq < small_angle_sq<S>()) {
    const S t2 = theta_sq, t4 = t2 * t2, t6 = t4 * t2;
    return S(1) / S(12) + t2 / S(720) + t4 / S(30240) + t6 / S(1209600);
  }
  using std::cos;
  using std::sin;
  using std::sqrt;
  const S theta = sqrt(theta_sq);
  const S half = theta / S(2);
  return S(1) / theta_sq - cos(half) / (S(2) * theta * sin(half));
}

// Fixed-size block assignment instead of comma initialisers: GCC 12 reports a false
// -Warray-bounds on Eigen's dynamic-block packet path for float 3-vectors at -O3.
template <typename S>
Vec6<S> stack(const Vec3<S>& top, const Vec3<S>& bottom) {
  Vec6<S> v;
  v.template head<3>() = top;
  v.template tail<3>() = bottom;
  return v;
}

/// [[a, b], [0, d]] from 3x3 blocks.
template <typename S>
Mat6<S> upper_block_triangular(const Mat3<S>& a, const Mat3<S>& b, const Mat3<S>& d) {
  Mat6<S> m;
  m.template topLeftCorner<3, 3>() = a;
  m.template topRightCorner<3, 3>() = b;
  m.template bottomLeftCorner<3, 3>().setZero();
  m.template bottomRightCorner<3, 3>() = d;
  return m;
}

}  // namespace lie_detail

// ---------------------------------------------------------------------------------------------
// hat / vee

/// The skew matrix [v]x with [v]x w = v x w.
template <typename Derived>
Mat3<typename Derived::Scalar> hat(const Eigen::MatrixBase<Derived>& v) {
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 1,
                "hat expects a 3-vector");
  using S = typename Derived::Scalar;
  Mat3<S> m;
  m << S(0), -v(2), v(1), v(2), S(0), -v(0), -v(1), v(0), S(0);
  return m;
}

/// Inverse of hat. Reads the skew-symmetric part (M - M^T) / 2, so any matrix is accepted.
template <typename Derived>
Vec3<typename Derived::Scalar> vee(const Eigen::MatrixBase<Derived>& m) {
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 3,
                "vee expects a 3x3 matrix");
  using S = typename Derived::Scalar;
  return Vec3<S>(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1)) / S(2);
}

/// The 4x4 matrix of se(3) for xi = [rho; phi]: [[phi]x, rho; 0, 0].
template <typename Derived>
Eigen::Matrix<typename Derived::Scalar, 4, 4> hat6(const Eigen::MatrixBase<Derived>& xi) {
  static_assert(Derived::RowsAtCompileTime == 6 && Derived::ColsAtCompileTime == 1,
                "hat6 expects a 6-vector [rho; phi]");
  using S = typename Derived::Scalar;
  Eigen::Matrix<S, 4, 4> m = Eigen::Matrix<S, 4, 4>::Zero();
  m.template topLeftCorner<3, 3>() = hat(xi.template tail<3>());
  m.template topRightCorner<3, 1>() = xi.template head<3>();
  return m;
}

/// Inverse of hat6: [rho; phi].
template <typename Derived>
Vec6<typename Derived::Scalar> vee6(const Eigen::MatrixBase<Derived>& m) {
  static_assert(Derived::RowsAtCompileTime == 4 && Derived::ColsAtCompileTime == 4,
                "vee6 expects a 4x4 matrix");
  using S = typename Derived::Scalar;
  return lie_detail::stack<S>(m.template topRightCorner<3, 1>(),
                              vee(m.template topLeftCorner<3, 3>()));
}

// ---------------------------------------------------------------------------------------------
// SO(3)

/// Rodrigues: exp([phi]x) = I + a K + b K^2 with K = [phi]x.
template <typename Derived>
Mat3<typename Derived::Scalar> so3_exp(const Eigen::MatrixBase<Derived>& phi_in) {
  using S = typename Derived::Scalar;
  const Vec3<S> phi = phi_in;
  const auto k = lie_detail::so3_coefficients(phi.squaredNorm());
  const Mat3<S> K = hat(phi);
  return Mat3<S>::Identity() + k.a * K + k.b * (K * K);
}

/// The rotation vector of R, with |phi| in [0, pi].
/// The angle comes from atan2(|skew part|, trace part), accurate at every angle. The axis comes
/// from the skew part (R - R^T)/2 = sin(theta) [a]x away from pi; near pi, where sin(theta)
/// vanishes, from the symmetric part (R + R^T)/2 - cos(theta) I = (1 - cos(theta)) a a^T, with
/// the sign taken from the skew part.
template <typename Derived>
Vec3<typename Derived::Scalar> so3_log(const Eigen::MatrixBase<Derived>& R_in) {
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 3,
                "so3_log expects a 3x3 matrix");
  using S = typename Derived::Scalar;
  using std::atan2;
  const Mat3<S> R = R_in;
  const Vec3<S> w = vee(R);  // sin(theta) * axis
  const S sin_theta = w.norm();
  const S cos_theta = (R.trace() - S(1)) / S(2);
  const S theta = atan2(sin_theta, cos_theta);

  if (cos_theta > S(-0.5)) {  // theta < 2pi/3: dividing by sin(theta) is well conditioned
    const S theta_sq = theta * theta;
    if (theta_sq < lie_detail::small_angle_sq<S>()) {
      const S t4 = theta_sq * theta_sq;
      const S theta_over_sin =
          S(1) + theta_sq / S(6) + S(7) * t4 / S(360) + S(31) * t4 * theta_sq / S(15120);
      return theta_over_sin * w;
    }
    return (theta / sin_theta) * w;
  }

  const Mat3<S> sym = (R + R.transpose()) / S(2) - cos_theta * Mat3<S>::Identity();
  Eigen::Index k = 0;
  sym.diagonal().maxCoeff(&k);  // the column with the largest |a_k|: best conditioned
  Vec3<S> axis = sym.col(k);
  const S norm = axis.norm();
  if (!(norm > S(0))) return (theta / sin_theta) * w;  // not a rotation; best effort
  axis /= norm;  // axis(k) > 0: the sign kept when the skew part is exactly zero (theta = pi)
  // At theta = pi both signs are right, so a skew part that is only rounding may pick either.
  if (axis.dot(w) < S(0)) axis = -axis;
  return theta * axis;
}

/// J_l(phi) = I + b K + c K^2.
template <typename Derived>
Mat3<typename Derived::Scalar> so3_left_jacobian(const Eigen::MatrixBase<Derived>& phi_in) {
  using S = typename Derived::Scalar;
  const Vec3<S> phi = phi_in;
  const auto k = lie_detail::so3_coefficients(phi.squaredNorm());
  const Mat3<S> K = hat(phi);
  return Mat3<S>::Identity() + k.b * K + k.c * (K * K);
}

/// J_r(phi) = J_l(-phi) = I - b K + c K^2.
template <typename Derived>
Mat3<typename Derived::Scalar> so3_right_jacobian(const Eigen::MatrixBase<Derived>& phi_in) {
  using S = typename Derived::Scalar;
  const Vec3<S> phi = phi_in;
  return so3_left_jacobian(Vec3<S>(-phi));
}

/// J_l^-1(phi) = I - K/2 + d K^2 (singular at |phi| = 2 pi).
template <typename Derived>
Mat3<typename Derived::Scalar> so3_left_jacobian_inverse(const Eigen::MatrixBase<Derived>& phi_in) {
  using S = typename Derived::Scalar;
  const Vec3<S> phi = phi_in;
  const S d = lie_detail::so3_inverse_jacobian_coefficient(phi.squaredNorm());
  const Mat3<S> K = hat(phi);
  return Mat3<S>::Identity() - K / S(2) + d * (K * K);
}

/// J_r^-1(phi) = J_l^-1(-phi) = I + K/2 + d K^2.
template <typename Derived>
Mat3<typename Derived::Scalar> so3_right_jacobian_inverse(
    const Eigen::MatrixBase<Derived>& phi_in) {
  using S = typename Derived::Scalar;
  const Vec3<S> phi = phi_in;
  return so3_left_jacobian_inverse(Vec3<S>(-phi));
}

/// The rotation nearest to M in the Frobenius norm (SVD, det +1): re-orthonormalises a matrix
/// that drifted through products or came from a file with few digits.
template <typename Derived>
Mat3<typename Derived::Scalar> nearest_rotation(const Eigen::MatrixBase<Derived>& m) {
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 3,
                "nearest_rotation expects a 3x3 matrix");
  using S = typename Derived::Scalar;
  const Mat3<S> M = m;
  const Eigen::JacobiSVD<Mat3<S>> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Mat3<S>& U = svd.matrixU();
  const Mat3<S>& V = svd.matrixV();
  // Flip the direction of the smallest singular value when U V^T would be a reflection.
  Vec3<S> signs(S(1), S(1), (U * V.transpose()).determinant() < S(0) ? S(-1) : S(1));
  return U * signs.asDiagonal() * V.transpose();
}

// ---------------------------------------------------------------------------------------------
// SE(3)

/// exp([rho; phi]) = (exp(phi), J_l(phi) rho).
template <typename Derived>
Isometry3<typename Derived::Scalar> se3_exp(const Eigen::MatrixBase<Derived>& xi_in) {
  static_assert(Derived::RowsAtCompileTime == 6 && Derived::ColsAtCompileTime == 1,
                "se3_exp expects a 6-vector [rho; phi]");
  using S = typename Derived::Scalar;
  const Vec6<S> xi = xi_in;
  const Vec3<S> rho = xi.template head<3>();
  const Vec3<S> phi = xi.template tail<3>();
  const auto k = lie_detail::so3_coefficients(phi.squaredNorm());
  const Mat3<S> K = hat(phi);
  const Mat3<S> K2 = K * K;
  Isometry3<S> T = Isometry3<S>::Identity();
  T.linear() = Mat3<S>::Identity() + k.a * K + k.b * K2;
  T.translation() = (Mat3<S>::Identity() + k.b * K + k.c * K2) * rho;
  return T;
}

/// log(T) = [J_l^-1(phi) t; phi] with phi = so3_log(R).
template <typename S>
Vec6<S> se3_log(const Isometry3<S>& T) {
  const Vec3<S> phi = so3_log(T.linear());
  const Vec3<S> t = T.translation();
  const Vec3<S> rho = so3_left_jacobian_inverse(phi) * t;
  return lie_detail::stack(rho, phi);
}

namespace lie_detail {

/// The upper-right block Q(rho, phi) of the SE(3) left Jacobian.
template <typename S>
Mat3<S> se3_q_block(const Vec3<S>& rho, const Vec3<S>& phi) {
  const S t2 = phi.squaredNorm();
  S c1, c2, c3;  // (t - sin t)/t^3, (t^2 + 2 cos t - 2)/(2 t^4), (2t - 3 sin t + t cos t)/(2 t^5)
  if (t2 < small_angle_sq<S>()) {
    const S t4 = t2 * t2, t6 = t4 * t2;
    c1 = S(1) / S(6) - t2 / S(120) + t4 / S(5040) - t6 / S(362880);
    c2 = S(1) / S(24) - t2 / S(720) + t4 / S(40320) - t6 / S(3628800);
    c3 = S(1) / S(120) - t2 / S(2520) + t4 / S(120960) - t6 / S(9979200);
  } else {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const S t = sqrt(t2);
    const S s = sin(t), c = cos(t);
    const S sin_half = sin(t / S(2));
    const S t4 = t2 * t2;
    c1 = (t - s) / (t2 * t);
    c2 = (t2 - S(4) * sin_half * sin_half) / (S(2) * t4);  // 2 cos t - 2 = -4 sin^2(t/2)
    c3 = (S(2) * t - S(3) * s + t * c) / (S(2) * t4 * t);
  }
  const Mat3<S> P = hat(phi);
  const Mat3<S> Rh = hat(rho);
  const Mat3<S> PR = P * Rh;
  const Mat3<S> RP = Rh * P;
  const Mat3<S> PRP = PR * P;
  const Mat3<S> PPR = P * PR;
  return Rh / S(2) + c1 * (PR + RP + PRP) + c2 * (PPR + RP * P - S(3) * PRP) +
         c3 * (PRP * P + PPR * P);
}

}  // namespace lie_detail

/// The 6x6 left Jacobian of SE(3) for xi = [rho; phi]: [[J_l(phi), Q], [0, J_l(phi)]].
template <typename Derived>
Mat6<typename Derived::Scalar> se3_left_jacobian(const Eigen::MatrixBase<Derived>& xi_in) {
  static_assert(Derived::RowsAtCompileTime == 6 && Derived::ColsAtCompileTime == 1,
                "se3_left_jacobian expects a 6-vector [rho; phi]");
  using S = typename Derived::Scalar;
  const Vec6<S> xi = xi_in;
  const Vec3<S> rho = xi.template head<3>();
  const Vec3<S> phi = xi.template tail<3>();
  const Mat3<S> J = so3_left_jacobian(phi);
  return lie_detail::upper_block_triangular<S>(J, lie_detail::se3_q_block(rho, phi), J);
}

/// J_r(xi) = J_l(-xi).
template <typename Derived>
Mat6<typename Derived::Scalar> se3_right_jacobian(const Eigen::MatrixBase<Derived>& xi_in) {
  using S = typename Derived::Scalar;
  const Vec6<S> xi = xi_in;
  return se3_left_jacobian(Vec6<S>(-xi));
}

/// [[J^-1, -J^-1 Q J^-1], [0, J^-1]] with J = J_l(phi).
template <typename Derived>
Mat6<typename Derived::Scalar> se3_left_jacobian_inverse(const Eigen::MatrixBase<Derived>& xi_in) {
  static_assert(Derived::RowsAtCompileTime == 6 && Derived::ColsAtCompileTime == 1,
                "se3_left_jacobian_inverse expects a 6-vector [rho; phi]");
  using S = typename Derived::Scalar;
  const Vec6<S> xi = xi_in;
  const Vec3<S> rho = xi.template head<3>();
  const Vec3<S> phi = xi.template tail<3>();
  const Mat3<S> J_inv = so3_left_jacobian_inverse(phi);
  const Mat3<S> Q = lie_detail::se3_q_block(rho, phi);
  return lie_detail::upper_block_triangular<S>(J_inv, -J_inv * Q * J_inv, J_inv);
}

/// J_r^-1(xi) = J_l^-1(-xi).
template <typename Derived>
Mat6<typename Derived::Scalar> se3_right_jacobian_inverse(const Eigen::MatrixBase<Derived>& xi_in) {
  using S = typename Derived::Scalar;
  const Vec6<S> xi = xi_in;
  return se3_left_jacobian_inverse(Vec6<S>(-xi));
}

/// Ad_T for the [rho; phi] order: [[R, [t]x R], [0, R]], so that exp(Ad_T xi) = T exp(xi) T^-1.
template <typename S>
Mat6<S> adjoint(const Isometry3<S>& T) {
  const Mat3<S> R = T.linear();
  const Vec3<S> t = T.translation();
  return lie_detail::upper_block_triangular<S>(R, hat(t) * R, R);
}

// ---------------------------------------------------------------------------------------------
// Interpolation

/// Geodesic interpolation R0 exp(alpha log(R0^T R1)); alpha outside [0, 1] extrapolates.
template <typename D0, typename D1>
Mat3<typename D0::Scalar> slerp(const Eigen::MatrixBase<D0>& R0_in,
                                const Eigen::MatrixBase<D1>& R1_in, typename D0::Scalar alpha) {
  using S = typename D0::Scalar;
  const Mat3<S> R0 = R0_in;
  const Mat3<S> R1 = R1_in;
  const Vec3<S> step = so3_log(R0.transpose() * R1);
  return R0 * so3_exp(alpha * step);
}

/// Quaternion form of slerp (the result is normalised; q and -q give the same answer).
template <typename S>
Eigen::Quaternion<S> slerp(const Eigen::Quaternion<S>& q0, const Eigen::Quaternion<S>& q1,
                           lie_detail::non_deduced_t<S> alpha) {
  const Mat3<S> R =
      slerp(q0.normalized().toRotationMatrix(), q1.normalized().toRotationMatrix(), alpha);
  return Eigen::Quaternion<S>(R).normalized();
}

/// Rotation by slerp, translation linear: T(alpha) with T(0) = T0, T(1) = T1. alpha outside
/// [0, 1] extrapolates (time synchronisation samples poses slightly beyond a frame pair).
template <typename S>
Isometry3<S> interpolate(const Isometry3<S>& T0, const Isometry3<S>& T1,
                         lie_detail::non_deduced_t<S> alpha) {
  Isometry3<S> T = Isometry3<S>::Identity();
  T.linear() = slerp(T0.linear(), T1.linear(), alpha);
  T.translation() = (S(1) - alpha) * T0.translation() + alpha * T1.translation();
  return T;
}

// ---------------------------------------------------------------------------------------------
// Roll, pitch, yaw

/// R = Rz(yaw) Ry(pitch) Rx(roll), radians (ROS convention: x forward, rotations about the
/// fixed x, then y, then z axes).
template <typename S>
Mat3<S> rotation_from_rpy(S roll, S pitch, S yaw) {
  using std::cos;
  using std::sin;
  const S cr = cos(roll), sr = sin(roll), cp = cos(pitch), sp = sin(pitch), cy = cos(yaw),
          sy = sin(yaw);
  Mat3<S> R;
  R << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,   //
      -sp, cp * sr, cp * cr;
  return R;
}

/// [roll, pitch, yaw] with roll, yaw in (-pi, pi] and pitch in [-pi/2, pi/2].
/// At gimbal lock (pitch = +-pi/2) only roll -+ yaw is defined: roll is set to 0.
/// The yaw and pitch are read after removing the found roll, so rotation_from_rpy of the result
/// reproduces R to rounding even where roll itself is ill-conditioned (near the lock).
template <typename Derived>
Vec3<typename Derived::Scalar> rpy_from_rotation(const Eigen::MatrixBase<Derived>& R_in) {
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 3,
                "rpy_from_rotation expects a 3x3 matrix");
  using S = typename Derived::Scalar;
  using std::atan2;
  using std::hypot;
  const Mat3<S> R = R_in;
  // Row 2 is [-sin p, cos p sin r, cos p cos r]: roll is lost when cos p is rounding noise.
  const S cos_pitch = hypot(R(2, 1), R(2, 2));
  const S roll =
      cos_pitch > S(4) * std::numeric_limits<S>::epsilon() ? atan2(R(2, 1), R(2, 2)) : S(0);
  using std::cos;
  using std::sin;
  const S cr = cos(roll), sr = sin(roll);
  // M = R Rx(roll)^T = Rz(yaw) Ry(pitch) = [[cy cp, -sy, cy sp], [sy cp, cy, sy sp], [-sp, 0, cp]]
  const S m01 = R(0, 1) * cr - R(0, 2) * sr;
  const S m11 = R(1, 1) * cr - R(1, 2) * sr;
  const S m22 = R(2, 1) * sr + R(2, 2) * cr;
  const S yaw = atan2(-m01, m11);
  const S pitch = atan2(-R(2, 0), m22 > S(0) ? m22 : S(0));  // cos(pitch) >= 0 by convention
  return Vec3<S>(roll, pitch, yaw);
}

}  // namespace ulc
