// Robust kernels for iteratively reweighted least squares (IRLS).
//
// Conventions this header owns:
//   - A kernel rho(r) replaces the squared residual r^2 / 2 of a least-squares cost; `scale` k
//     (> 0, in the residual's unit, metres for point-to-plane) is where it starts to bend.
//   - The IRLS weight is w(r) = rho'(r) / r, so that a Gauss-Newton step on sum w r^2 / 2 with
//     w frozen has the same gradient as sum rho(r). Every w is in (0, 1] with w(0) = 1.
//       none (least squares): rho = r^2 / 2,                         w = 1
//       huber:                rho = r^2 / 2 (|r| <= k),  k |r| - k^2 / 2 (else)
//                             w = 1 (|r| <= k), k / |r| (else)
//       cauchy:               rho = k^2 / 2 log(1 + r^2 / k^2),      w = 1 / (1 + r^2 / k^2)
//       geman_mcclure:        rho = k^2 r^2 / (2 (k^2 + r^2)),       w = k^4 / (k^2 + r^2)^2
//   - Huber stays convex (outliers keep a pull that grows like |r|); Cauchy and Geman-McClure
//     redescend (the pull of a far outlier goes to zero), Geman-McClure fastest.
//   - A kernel with a scale that is not finite and positive acts as `none`.
#pragma once

#include <cmath>

namespace ulc {

enum class RobustKernelType { none, huber, cauchy, geman_mcclure };

inline const char* to_string(RobustKernelType t) {
  switch (t) {
    case RobustKernelType::huber:
      return "huber";
    case RobustKernelType::cauchy:
      return "cauchy";
    case RobustKernelType::geman_mcclure:
      return "geman_mcclure";
    default:
      return "none";
  }
}

struct RobustKernel {
  RobustKernelType type = RobustKernelType::none;
  double scale = 1.0;

  static RobustKernel least_squares() { return {}; }
  static RobustKernel huber(double k) { return {RobustKernelType::huber, k}; }
  static RobustKernel cauchy(double k) { return {RobustKernelType::cauchy, k}; }
  static RobustKernel geman_mcclure(double k) { return {RobustKernelType::geman_mcclure, k}; }

  bool active() const {
    return type != RobustKernelType::none && scale > 0.0 && std::isfinite(scale);
  }

  /// The IRLS weight rho'(r) / r, in (0, 1].
  double weight(double r) const {
    if (!active()) return 1.0;
    const double k2 = scale * scale;
    const double r2 = r * r;
    switch (type) {
      case RobustKernelType::huber: {
        const double a = std::abs(r);
        return a <= scale ? 1.0 : scale / a;
      }
      case RobustKernelType::cauchy:
        return 1.0 / (1.0 + r2 / k2);
      case RobustKernelType::geman_mcclure: {
        const double q = k2 / (k2 + r2);
        return q * q;
      }
      default:
        return 1.0;
    }
  }

  /// psi'(r) = d(weight(r) r) / dr = rho''(r): the curvature the kernel gives a residual (the
  /// "bread" of an M-estimator's sandwich covariance; negative where the kernel turns a residual
  /// away, beyond scale / sqrt(3) for Geman-McClure and beyond scale for Cauchy).
  double curvature(double r) const {
    if (!active()) return 1.0;
    const double k2 = scale * scale;
    const double r2 = r * r;
    switch (type) {
      case RobustKernelType::huber:
        return std::abs(r) <= scale ? 1.0 : 0.0;
      case RobustKernelType::cauchy:
        return k2 * (k2 - r2) / ((k2 + r2) * (k2 + r2));
      case RobustKernelType::geman_mcclure: {
        const double q = k2 / (k2 + r2);
        return q * q * (k2 - 3.0 * r2) / (k2 + r2);
      }
      default:
        return 1.0;
    }
  }

  /// The kernel's cost rho(r) (r^2 / 2 for least squares).
  double rho(double r) const {
    const double r2 = r * r;
    if (!active()) return 0.5 * r2;
    const double k2 = scale * scale;
    switch (type) {
      case RobustKernelType::huber: {
        const double a = std::abs(r);
        return a <= scale ? 0.5 * r2 : scale * a - 0.5 * k2;
      }
      case RobustKernelType::cauchy:
        return 0.5 * k2 * std::log1p(r2 / k2);
      case RobustKernelType::geman_mcclure:
        return 0.5 * k2 * r2 / (k2 + r2);
      default:
        return 0.5 * r2;
    }
  }
};

}  // namespace ulc
