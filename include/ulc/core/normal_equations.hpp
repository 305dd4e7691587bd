// NormalEquations6: the Gauss-Newton system of a 6-parameter least-squares problem, summed
// residual by residual (the building block of point-to-plane registration).
//
// Conventions this header owns:
//   - Cost F(x) = 1/2 * sum_i w_i r_i(x)^2, with J_i = d r_i / d x (a 1x6 row).
//     H = sum w J^T J, b = sum w J^T r, so the Gauss-Newton step solves H dx = -b.
//   - `cost` holds sum w r^2 (without the 1/2): the weighted sum of squared residuals.
//   - H is exactly symmetric (each off-diagonal product is computed once).
//   - Everything accumulates in double, whatever the scalar of J and r.
//   - operator+ joins two partial systems (for deterministic_reduce in parallel_reduce.hpp):
//     it is a plain element-wise sum, so a fixed join order gives fixed bits.
#pragma once

#include <cstddef>

#include <Eigen/Core>

#include "ulc/core/types.hpp"

namespace ulc {

struct NormalEquations6 {
  Mat6d H = Mat6d::Zero();
  Vec6d b = Vec6d::Zero();
  double cost = 0.0;
  std::size_t count = 0;

  /// Adds one residual r with Jacobian J (a 1x6 row or a 6-vector, any scalar) and weight w.
  template <typename Derived>
  void add(const Eigen::MatrixBase<Derived>& J, double r, double w = 1.0) {
    static_assert(Derived::IsVectorAtCompileTime && Derived::SizeAtCompileTime == 6,
                  "NormalEquations6::add: J must have 6 entries (1x6 or 6x1)");
    Vec6d j;
    for (Eigen::Index i = 0; i < 6; ++i) j[i] = static_cast<double>(J.derived().coeff(i));
    // Upper triangle computed once and mirrored: H stays exactly symmetric, bit for bit.
    for (Eigen::Index a = 0; a < 6; ++a) {
      for (Eigen::Index c = a; c < 6; ++c) {
        const double v = w * (j[a] * j[c]);
        H(a, c) += v;
        if (c != a) H(c, a) += v;
      }
    }
    b.noalias() += (w * r) * j;
    cost += w * r * r;
    ++count;
  }

  NormalEquations6& operator+=(const NormalEquations6& other) {
    H += other.H;
    b += other.b;
    cost += other.cost;
    count += other.count;
    return *this;
  }
  friend NormalEquations6 operator+(NormalEquations6 a, const NormalEquations6& b) {
    a += b;
    return a;
  }
};

}  // namespace ulc
