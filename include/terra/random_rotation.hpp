// Seeded, portable random rotations uniform on SO(3), for benchmarks, profiling and tests.
//
// The generator is SplitMix64 (fixed arithmetic, so the same seed gives the same rotations on
// every platform, unlike the std:: distributions), and the rotation is Shoemake's uniform unit
// quaternion from three uniform numbers in [0, 1).
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

#include "ulc/core/types.hpp"

namespace terra {

class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

/// A rotation uniform on SO(3) (Haar measure).
inline ulc::Mat3d random_rotation(SplitMix64& rng) {
  constexpr double kTwoPi = 6.28318530717958647692;
  const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const Eigen::Quaterniond q(b * std::cos(kTwoPi * u3), a * std::sin(kTwoPi * u2),
                             a * std::cos(kTwoPi * u2), b * std::sin(kTwoPi * u3));
  return q.normalized().toRotationMatrix();
}

}  // namespace terra
