// The match-then-solve loop of every registration in ULC: point_to_plane.hpp's (TERRA's
// successors, JEEP, the odometry, HOTS's links) and HOTS's whole-sequence step
// (hots/sequence_extrinsic.hpp). The residual is the caller's policy, as small_gicp's factors
// are: the loop only decides when to search correspondences again and when to stop.
//
//   - Each iteration matches once (the correspondences then stay fixed), then takes
//     Gauss-Newton steps with IRLS weights refreshed at every step, until a step is below the
//     tolerances or max_solver_iterations steps were taken.
//   - Converged: a whole iteration moved the estimate less than the tolerances (the matches it
//     was made with still stand). Starved: a search found fewer than min_correspondences; the
//     loop stops there.
//
// The Problem policy:
//   typename Problem::State                          the estimate (copyable)
//   std::size_t match(const State& x)                searches correspondences at x; returns how
//                                                    many were found
//   bool step(State& x)                              one Gauss-Newton step on the current
//                                                    matches; true when it was below tolerance
//   bool moved_little(const State& a, const State& b) the iteration's convergence test
#pragma once

#include <cstddef>

namespace ulc {

struct GaussNewtonLimits {
  int max_iterations = 1;         ///< correspondence searches
  int max_solver_iterations = 1;  ///< Gauss-Newton steps per search
  std::size_t min_correspondences = 0;
};

struct GaussNewtonRun {
  int iterations = 0;         ///< correspondence searches made
  int solver_iterations = 0;  ///< steps taken
  bool converged = false;
  bool starved = false;
};

template <class Problem>
GaussNewtonRun gauss_newton(Problem& problem, typename Problem::State& x,
                            const GaussNewtonLimits& limits) {
  GaussNewtonRun run;
  for (int it = 0; it < limits.max_iterations; ++it) {
    const std::size_t found = problem.match(x);
    ++run.iterations;
    if (found < limits.min_correspondences) {
      run.starved = true;
      return run;
    }
    const typename Problem::State matched = x;
    for (int step = 0; step < limits.max_solver_iterations; ++step) {
      ++run.solver_iterations;
      if (problem.step(x)) break;
    }
    if (problem.moved_little(matched, x)) {
      run.converged = true;
      return run;
    }
  }
  return run;
}

}  // namespace ulc
