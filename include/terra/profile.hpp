// A deterministic, seedable entry point for benchmarks and profilers: one TERRA case from two
// clouds, with the target LiDAR turned by a random rotation drawn from a seed.
//
//   perf record ./my_profiler   (calling terra::profile_case in a loop over seeds)
//
// The target cloud is turned by Q (uniform on SO(3), random_rotation.hpp): every point p
// becomes Q p, as if the target LiDAR had been mounted turned by Q^T. The ground truth
// R_base_target therefore becomes R_base_target Q^T. Same inputs and seed: same result, bit for
// bit, with any number of threads.
#pragma once

#include <cstdint>
#include <vector>

#include "terra/lattice.hpp"
#include "terra/random_rotation.hpp"
#include "terra/search.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/types.hpp"

namespace terra {

struct ProfileCase {
  SearchResult result;
  ulc::Mat3d applied = ulc::Mat3d::Identity();  ///< Q, applied to the target's points
  ulc::Mat3d truth = ulc::Mat3d::Identity();    ///< R_base_target of the turned target
  double error_deg = 0.0;                       ///< e_rot of the result against truth
};

/// `target` turned by a rotation drawn from `seed`, then estimate_rotation against `base`.
/// R_base_target is the untouched pair's ground truth (identity for a cloud against itself).
template <class BaseCloud, class TargetCloud>
ProfileCase profile_case(const Lattice& lattice, const BaseCloud& base, const TargetCloud& target,
                         const ulc::Mat3d& R_base_target, std::uint64_t seed,
                         const SearchParams& params = {}) {
  using S = ulc::traits::scalar_t<TargetCloud>;
  ProfileCase out;
  SplitMix64 rng(seed);
  out.applied = random_rotation(rng);
  out.truth = R_base_target * out.applied.transpose();
  const ulc::Mat3<S> Q = out.applied.template cast<S>();
  std::vector<ulc::Vec3<S>> turned(ulc::traits::size(target));
  for (std::size_t i = 0; i < turned.size(); ++i) turned[i] = Q * ulc::traits::point(target, i);
  out.result = estimate_rotation(lattice, base, turned, params);
  out.error_deg = ulc::rotation_error_rad(out.truth, out.result.rotation) * ulc::kDegPerRad;
  return out;
}

}  // namespace terra
