// Random numbers for the simulator, as pure functions of integer keys.
//
// Conventions this header owns:
//   - Every random draw is a function of (seed, stream ids, counter): nothing is drawn from a
//     shared generator, so results never depend on thread scheduling or on the order in which
//     frames or rays are processed. 1 and N threads give the same bits.
//   - mix64 is the SplitMix64 finaliser (a bijection on 64 bits with full avalanche); keys are
//     chained with hash_key(a, b, ...). Streams that must not correlate get distinct salt
//     constants (see the k*Stream constants next to their users).
//   - Uniforms are 53-bit doubles in [0, 1); normals use the polar method on such uniforms.
//     The generators are specified here bit for bit (no std:: distributions, whose output
//     differs between standard libraries), so a seed means the same scene everywhere.
#pragma once

#include <cmath>
#include <cstdint>

namespace ulc::sim {

/// SplitMix64 finaliser: a well-mixed bijection of 64-bit integers.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// A key for the pair (a, b); order matters.
constexpr std::uint64_t hash_key(std::uint64_t a, std::uint64_t b) {
  return mix64(a ^ mix64(b + 0x632be59bd9b4e019ULL));
}
template <typename... Rest>
constexpr std::uint64_t hash_key(std::uint64_t a, std::uint64_t b, Rest... rest) {
  return hash_key(hash_key(a, b), static_cast<std::uint64_t>(rest)...);
}

/// [0, 1) from the top 53 bits.
constexpr double unit_double(std::uint64_t bits) {
  return static_cast<double>(bits >> 11) * (1.0 / 9007199254740992.0);
}

/// Draws from a counter: the i-th draw of a key is mix64(key + i), independent of other keys.
/// Cheap to create per ray; a long-lived one serves as the sequential generator of scene
/// construction (deterministic because construction itself is serial).
class CounterRng {
 public:
  explicit constexpr CounterRng(std::uint64_t key) : key_(key) {}

  constexpr std::uint64_t next_u64() { return mix64(key_ + 0x9e3779b97f4a7c15ULL * ++counter_); }
  /// [0, 1)
  constexpr double uniform() { return unit_double(next_u64()); }
  /// [lo, hi)
  constexpr double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// An integer in [0, n); n > 0.
  std::uint64_t below(std::uint64_t n) {
    const auto v = static_cast<std::uint64_t>(uniform() * static_cast<double>(n));
    return v < n ? v : n - 1;
  }
  /// True with probability p.
  bool chance(double p) { return uniform() < p; }
  /// Standard normal (the second of each generated pair is kept for the next call).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double a, b;
    normal_pair(a, b);
    spare_ = b;
    has_spare_ = true;
    return a;
  }
  double normal(double mean, double sigma) { return mean + sigma * normal(); }
  /// A cheap, nearly normal variate (mean 0, variance 1) from one draw: the sum of four 16-bit
  /// uniforms (Irwin-Hall), tails cut at +-3.46. For small perturbations whose tails do not
  /// matter (angular jitter); measurement noise uses normal_pair.
  double approx_normal() {
    const std::uint64_t bits = next_u64();
    const double sum = static_cast<double>((bits & 0xffff) + ((bits >> 16) & 0xffff) +
                                           ((bits >> 32) & 0xffff) + (bits >> 48));
    return (sum * (1.0 / 65536.0) - 2.0) * 1.7320508075688772;
  }
  /// Two independent standard normals (Marsaglia's polar method: no trigonometry; the
  /// rejection loop draws further uniforms from the same counter, so it stays deterministic).
  void normal_pair(double& a, double& b) {
    double x, y, s;
    do {
      x = 2.0 * uniform() - 1.0;
      y = 2.0 * uniform() - 1.0;
      s = x * x + y * y;
    } while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * std::log(s) / s);
    a = x * f;
    b = y * f;
  }

 private:
  std::uint64_t key_;
  std::uint64_t counter_ = 0;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace ulc::sim
