// Point-to-plane registration by Gauss-Newton with robust IRLS weights (the paper's
// eq:pserror and its point Jacobian), for one source cloud or several "terms" sharing one pose.
//
// Conventions this header owns (see also registration_types.hpp):
//   - A term is a set of source points x with a target, and two fixed transforms around the
//     estimated pose T: the point compared with the target is z = post * T * pre * x.
//     One cloud: pre = post = identity. The pose phase of JEEP (eq:je_odom): base scan with
//     pre = post = identity, target scan with pre = C (and a time shift), post = C^-1.
//   - Residual r = n . (z - p) for the plane (p, n) matched to z; with y = T pre x and
//     u = R_post^T n, its Jacobian for T <- exp(xi) T is J = [u; y x u] (1x6, [rho; phi]).
//     For pre = post = I this is the paper's n^T [I, -[Tp]x]; for pre = C, post = C^-1 it is
//     its joint Jacobian n^T R_{C^-1} [I, -[T C p]x].
//   - Every iteration matches every source point once (gate: max_correspondence_distance; the
//     neighbour search is nearly all the cost), then takes Gauss-Newton steps with the matches
//     fixed: each weights a residual by term weight * kernel weight of its current value, sums
//     the normal equations with deterministic_reduce (fixed grain: same bits for any thread
//     count) and takes the truncated step of registration_conditioning.hpp.
//   - The reported cost, counts, Hessian and condition are evaluated at the returned pose.
//   - Nothing here throws, prints or allocates per point.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ulc/core/cloud.hpp"
#include "ulc/core/gauss_newton.hpp"
#include "ulc/core/kdtree.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/normal_equations.hpp"
#include "ulc/core/parallel_reduce.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/registration_conditioning.hpp"
#include "ulc/core/registration_types.hpp"
#include "ulc/core/robust_kernel.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// Source points sharing one target and one placement around the estimated pose.
template <typename S, class Target>
struct PointToPlaneTerm {
  const Vec3<S>* points = nullptr;
  std::size_t size = 0;
  const Target* target = nullptr;
  Isometry3d pre = Isometry3d::Identity();
  Isometry3d post = Isometry3d::Identity();
  double weight = 1.0;
};

/// z = post * T * pre * x and the residual's Jacobian, for one pose T.
class PointToPlaneGeometry {
 public:
  PointToPlaneGeometry(const Isometry3d& pre, const Isometry3d& T, const Isometry3d& post)
      : moved_(T * pre), post_(post), post_rotation_t_(post.linear().transpose()) {}

  /// y = T * pre * x (the frame the perturbation acts in).
  Vec3d pose_frame(const Vec3d& x) const { return moved_ * x; }
  /// z = post * y (the target frame).
  Vec3d target_frame(const Vec3d& y) const { return post_ * y; }

  /// r = n . (z - p); J (if given) = [u; y x u], u = R_post^T n.
  double residual(const Vec3d& y, const Vec3d& z, const PlaneMatch& plane, Vec6d* J) const {
    if (J) {
      const Vec3d u = post_rotation_t_ * plane.normal;
      J->head<3>() = u;
      J->tail<3>() = y.cross(u);
    }
    return plane.normal.dot(z - plane.point);
  }

 private:
  Isometry3d moved_;
  Isometry3d post_;
  Mat3d post_rotation_t_;
};

/// Everything one pass over the source points sums.
struct PointToPlaneSums {
  NormalEquations6 equations;
  double robust_cost = 0.0;
  std::size_t inliers = 0;
  double inlier_sq_sum = 0.0;
  double weight_sum = 0.0;
  Vec3d weighted_y = Vec3d::Zero();  ///< sum w y
  double weighted_yy = 0.0;          ///< sum w |y|^2

  PointToPlaneSums& operator+=(const PointToPlaneSums& o) {
    equations += o.equations;
    robust_cost += o.robust_cost;
    inliers += o.inliers;
    inlier_sq_sum += o.inlier_sq_sum;
    weight_sum += o.weight_sum;
    weighted_y += o.weighted_y;
    weighted_yy += o.weighted_yy;
    return *this;
  }

  /// Weighted centroid c and RMS distance L of the matched points from it (pose frame).
  Vec3d centre() const { return weight_sum > 0.0 ? Vec3d(weighted_y / weight_sum) : Vec3d::Zero(); }
  double spread() const {
    if (!(weight_sum > 0.0)) return 1.0;
    const double v = weighted_yy / weight_sum - centre().squaredNorm();
    return v > 0.0 ? std::sqrt(v) : 1e-9;
  }
};

/// The plane matched to each source point of each term (normal zero: no match).
using PointToPlaneMatches = std::vector<std::vector<PlaneMatch>>;

namespace detail {
// Matching is independent per point; the grain only sets the task size.
constexpr std::size_t kMatchGrain = 256;
}  // namespace detail

/// Matches every source point at pose T (gate: max_correspondence_distance). Returns the count.
template <typename S, class Target>
std::size_t match_point_to_plane(const std::vector<PointToPlaneTerm<S, Target>>& terms,
                                 const Isometry3d& T, double max_distance,
                                 PointToPlaneMatches& matches) {
  matches.resize(terms.size());
  std::size_t found = 0;
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const auto& term = terms[t];
    auto& out = matches[t];
    const bool active = term.points && term.target && term.weight > 0.0;
    out.assign(active ? term.size : 0, PlaneMatch{});
    if (!active) continue;
    const PointToPlaneGeometry geometry(term.pre, T, term.post);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, term.size, detail::kMatchGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        PlaneMatch plane;
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          const Vec3d z = geometry.target_frame(
                              geometry.pose_frame(term.points[i].template cast<double>()));
                          if (term.target->find_plane(z, max_distance, plane)) out[i] = plane;
                        }
                      });
    for (const PlaneMatch& m : out) found += m.normal.squaredNorm() > 0.0 ? 1 : 0;
  }
  return found;
}

/// The normal equations at pose T with the matches held fixed (IRLS weights at T's residuals).
template <typename S, class Target>
PointToPlaneSums sum_matched_point_to_plane(const std::vector<PointToPlaneTerm<S, Target>>& terms,
                                            const PointToPlaneMatches& matches, const Isometry3d& T,
                                            const RegistrationOptions& options) {
  PointToPlaneSums total;
  for (std::size_t t = 0; t < terms.size() && t < matches.size(); ++t) {
    const auto& term = terms[t];
    const auto& planes = matches[t];
    if (planes.size() != term.size || term.size == 0) continue;
    const PointToPlaneGeometry geometry(term.pre, T, term.post);
    const auto body = [&](std::size_t begin, std::size_t end, PointToPlaneSums acc) {
      Vec6d J;
      for (std::size_t i = begin; i < end; ++i) {
        const PlaneMatch& plane = planes[i];
        if (plane.normal.squaredNorm() == 0.0) continue;
        const Vec3d y = geometry.pose_frame(term.points[i].template cast<double>());
        const double r = geometry.residual(y, geometry.target_frame(y), plane, &J);
        const double w = term.weight * options.kernel.weight(r);
        acc.equations.add(J, r, w);
        acc.robust_cost += term.weight * options.kernel.rho(r);
        if (std::abs(r) <= options.inlier_distance) {
          ++acc.inliers;
          acc.inlier_sq_sum += r * r;
        }
        acc.weight_sum += w;
        acc.weighted_y += w * y;
        acc.weighted_yy += w * y.squaredNorm();
      }
      return acc;
    };
    const auto join = [](PointToPlaneSums a, const PointToPlaneSums& b) {
      a += b;
      return a;
    };
    total += deterministic_reduce(term.size, PointToPlaneSums{}, body, join, options.grain);
  }
  return total;
}

/// Matching and summing at pose T in one call.
template <typename S, class Target>
PointToPlaneSums sum_point_to_plane(const std::vector<PointToPlaneTerm<S, Target>>& terms,
                                    const Isometry3d& T, const RegistrationOptions& options) {
  PointToPlaneMatches matches;
  match_point_to_plane(terms, T, options.max_correspondence_distance, matches);
  return sum_matched_point_to_plane(terms, matches, T, options);
}

namespace detail {

inline bool valid_registration_options(const RegistrationOptions& o) {
  return o.max_iterations >= 1 && o.max_solver_iterations >= 1 &&
         o.max_correspondence_distance > 0.0 && std::isfinite(o.max_correspondence_distance) &&
         o.translation_tolerance >= 0.0 && o.rotation_tolerance >= 0.0 && o.min_condition >= 0.0 &&
         o.min_condition < 1.0 && o.grain >= 1;
}

template <typename S>
bool finite_pose(const Isometry3<S>& T) {
  return T.matrix().allFinite();
}

/// How far the motion T_old -> T_new moves the point c, and how far it turns.
inline bool small_motion(const Isometry3d& T_old, const Isometry3d& T_new, const Vec3d& c,
                         const RegistrationOptions& o) {
  const Isometry3d D = T_new * T_old.inverse();
  const double moved = (D * c - c).norm();
  const double turned = so3_log(D.linear()).norm();
  return moved < o.translation_tolerance && turned < o.rotation_tolerance;
}

/// Point-to-plane residuals over terms sharing the pose T, as gauss_newton.hpp's policy: each
/// step solves the truncated, scaled normal equations around the matched points' centre c, and
/// a move is small when it shifts c and turns less than the tolerances.
template <typename S, class Target>
struct PointToPlaneProblem {
  using State = Isometry3d;
  const std::vector<PointToPlaneTerm<S, Target>>& terms;
  const RegistrationOptions& options;
  PointToPlaneMatches matches;
  Vec3d centre;  ///< of the last step's matched points

  std::size_t match(const Isometry3d& T) {
    return match_point_to_plane(terms, T, options.max_correspondence_distance, matches);
  }
  bool step(Isometry3d& T) {
    const PointToPlaneSums sums = sum_matched_point_to_plane(terms, matches, T, options);
    centre = sums.centre();
    const ScaledSolve solve = solve_truncated(sums.equations.H, sums.equations.b, centre,
                                              sums.spread(), options.min_condition);
    const Isometry3d next = se3_exp(solve.step) * T;
    const bool small = small_motion(T, next, centre, options);
    T = next;
    return small;
  }
  bool moved_little(const Isometry3d& from, const Isometry3d& to) const {
    return small_motion(from, to, centre, options);
  }
};

}  // namespace detail

/// Gauss-Newton over several terms sharing the pose T (T_target_source for a single term), by
/// gauss_newton.hpp's loop on detail::PointToPlaneProblem.
template <typename S, class Target>
RegistrationResult<double> register_point_to_plane_terms(
    const std::vector<PointToPlaneTerm<S, Target>>& terms, const Isometry3d& initial,
    const RegistrationOptions& options = {}) {
  RegistrationResult<double> result;
  result.pose = initial;
  for (const auto& term : terms) result.source_points += term.target ? term.size : 0;
  if (!detail::valid_registration_options(options)) {
    result.status = RegistrationStatus::invalid_input;
    result.reason = "invalid registration options";
    return result;
  }
  if (!detail::finite_pose(initial)) {
    result.status = RegistrationStatus::invalid_input;
    result.reason = "initial pose is not finite";
    return result;
  }
  if (result.source_points == 0) {
    result.status = RegistrationStatus::invalid_input;
    result.reason = "no source points";
    return result;
  }

  detail::PointToPlaneProblem<S, Target> problem{terms, options, {}, Vec3d::Zero()};
  Isometry3d T = initial;
  const GaussNewtonRun run = gauss_newton(
      problem, T,
      {options.max_iterations, options.max_solver_iterations, options.min_correspondences});
  result.iterations = run.iterations;
  result.solver_iterations = run.solver_iterations;
  const bool converged = run.converged, starved = run.starved;
  PointToPlaneMatches& matches = problem.matches;

  result.pose = T;
  // Converged: T is within the tolerances of where the last matches were made, so they stand.
  if (!converged) match_point_to_plane(terms, T, options.max_correspondence_distance, matches);
  const PointToPlaneSums final_sums = sum_matched_point_to_plane(terms, matches, T, options);
  result.correspondences = final_sums.equations.count;
  result.inliers = final_sums.inliers;
  result.cost = final_sums.robust_cost;
  result.rmse = final_sums.inliers
                    ? std::sqrt(final_sums.inlier_sq_sum / static_cast<double>(final_sums.inliers))
                    : 0.0;
  result.hessian = final_sums.equations.H;
  result.condition =
      scaled_condition(final_sums.equations.H, final_sums.centre(), final_sums.spread());

  if (starved || result.correspondences < options.min_correspondences) {
    result.status = RegistrationStatus::too_few_correspondences;
    result.reason = "fewer correspondences than min_correspondences within the gate";
  } else if (result.condition < options.min_condition) {
    result.status = RegistrationStatus::degenerate;
    result.reason =
        "the correspondences leave a direction unconstrained (condition below "
        "min_condition)";
  } else if (!converged) {
    result.status = RegistrationStatus::not_converged;
    result.reason = "max_iterations reached before the updates fell below the tolerances";
  }
  return result;
}

/// Stages run in order, each starting where the previous one ended (coarse to fine: a wide
/// gate and a soft kernel find the basin, a tight kernel then ignores what the two clouds do
/// not share). Stops early on too_few_correspondences or invalid_input. The result is the last
/// stage's, with the iterations of all stages.
template <typename S, class Target>
RegistrationResult<double> register_point_to_plane_terms(
    const std::vector<PointToPlaneTerm<S, Target>>& terms, const Isometry3d& initial,
    const std::vector<RegistrationOptions>& stages) {
  RegistrationResult<double> result;
  result.pose = initial;
  if (stages.empty()) {
    result.status = RegistrationStatus::invalid_input;
    result.reason = "no registration stage";
    return result;
  }
  int iterations = 0, solver_iterations = 0;
  for (const RegistrationOptions& stage : stages) {
    result = register_point_to_plane_terms(terms, result.pose, stage);
    iterations += result.iterations;
    solver_iterations += result.solver_iterations;
    if (result.status == RegistrationStatus::too_few_correspondences ||
        result.status == RegistrationStatus::invalid_input)
      break;
  }
  result.iterations = iterations;
  result.solver_iterations = solver_iterations;
  return result;
}

/// Two stages that refine a guess within about 2 deg and 0.5 m to what the data allow:
/// gate `gate`, Geman-McClure 0.2 m, loose tolerances; then gate gate / 2, Geman-McClure
/// 0.05 m (a few times the noise of a LiDAR range), the default tolerances.
inline std::vector<RegistrationOptions> coarse_to_fine_stages(double gate = 1.0) {
  RegistrationOptions coarse;
  coarse.max_correspondence_distance = gate;
  coarse.kernel = RobustKernel::geman_mcclure(0.2);
  coarse.translation_tolerance = 1e-3;
  coarse.rotation_tolerance = 1e-4;
  RegistrationOptions fine;
  fine.max_correspondence_distance = gate / 2;
  fine.kernel = RobustKernel::geman_mcclure(0.05);
  return {coarse, fine};
}

namespace detail {

template <typename S>
RegistrationResult<S> cast_result(const RegistrationResult<double>& r) {
  RegistrationResult<S> out;
  out.status = r.status;
  out.reason = r.reason;
  out.pose = r.pose.template cast<S>();
  out.iterations = r.iterations;
  out.solver_iterations = r.solver_iterations;
  out.source_points = r.source_points;
  out.correspondences = r.correspondences;
  out.inliers = r.inliers;
  out.cost = r.cost;
  out.rmse = r.rmse;
  out.hessian = r.hessian;
  out.condition = r.condition;
  return out;
}

template <class SourceCloud>
std::vector<Vec3<traits::scalar_t<SourceCloud>>> finite_points(const SourceCloud& source) {
  using SourceScalar = traits::scalar_t<SourceCloud>;
  std::vector<Vec3<SourceScalar>> points;
  const std::size_t n = traits::size(source);
  points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3<SourceScalar> p = traits::point(source, i);
    if (is_finite_point(p)) points.push_back(p);
  }
  return points;
}

/// One source cloud as a single term: the common body of both register_point_to_plane
/// overloads (`how` is one RegistrationOptions or a list of stages).
template <typename S, class SourceCloud, class Target, class How>
RegistrationResult<S> register_one_source(const SourceCloud& source, const Target& target,
                                          const Isometry3<S>& initial, const How& how) {
  using SourceScalar = traits::scalar_t<SourceCloud>;
  const auto points = finite_points(source);
  std::vector<PointToPlaneTerm<SourceScalar, Target>> terms(1);
  terms[0].points = points.data();
  terms[0].size = points.size();
  terms[0].target = &target;
  return cast_result<S>(register_point_to_plane_terms(terms, initial.template cast<double>(), how));
}

}  // namespace detail

/// Registers `source` to `target` in stages (see above): the T_target_source that puts the
/// source's points on the target's planes, starting from `initial`.
template <typename S, class SourceCloud, class Target>
RegistrationResult<S> register_point_to_plane(const SourceCloud& source, const Target& target,
                                              const Isometry3<S>& initial,
                                              const std::vector<RegistrationOptions>& stages) {
  return detail::register_one_source(source, target, initial, stages);
}

/// Registers `source` to `target`: the T_target_source that puts the source's points on the
/// target's planes, starting from `initial`.
template <typename S, class SourceCloud, class Target>
RegistrationResult<S> register_point_to_plane(const SourceCloud& source, const Target& target,
                                              const Isometry3<S>& initial,
                                              const RegistrationOptions& options = {}) {
  return detail::register_one_source(source, target, initial, options);
}

}  // namespace ulc
