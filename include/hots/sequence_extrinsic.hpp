// The extrinsic and the clock offset from the whole sequence at once, after the pose graph and
// the time synchronisation (paper Sec. "Pose Refinement by Hierarchical Optimization": "use all
// data collectively to estimate the extrinsics").
//
// Every target frame j is placed in the world through the base's refined trajectory:
//   z = T_a(t_j + dt) * C * x,    x a point of b's frame j (deskewed to its timestamp t_j),
// and compared with the base's submaps (point to plane, the paper's eq:pserror). One rigid C
// and one offset dt explain every frame, so the estimate averages over the whole drive; only
// the base's poses enter (the target's own poses never do), so the target's odometry errors do
// not leak into C. Time synchronisation by the extrinsics' spread (time_sync.hpp, the paper's
// eq:var) gives the starting dt and C; this refines both.
//
// Conventions this header owns:
//   - World = the frame of the base's poses world_a (T_world_a at times_a, a's clock). Clock
//     offset as in docs/design.md: t_a = t_b + dt. T_a(t) interpolates world_a (slerp + linear).
//   - Targets: the base's layer-`target_layer` submaps of the hierarchy (clouds anchored at
//     their first frame), voxel-thinned at target_voxel, with PCA planes. Frame j's points go
//     to the submap whose time span holds t_j + dt (else the nearest), as one point-to-plane
//     term with post = T_world_anchor^-1 T_a(t_j + dt) around the estimated C (left
//     perturbation, point_to_plane.hpp).
//   - C and dt are solved together by Gauss-Newton on the 7 parameters [rho; phi; dt]
//     (gauss_newton.hpp's loop with SequenceProblem as its residual: robust IRLS weights,
//     matches refreshed every iteration, stages coarse to fine as in point_to_plane.hpp). The
//     residual's dt column is n . (d post / d dt) y, y = C x, with d post / d dt by a central
//     difference of the interpolated trajectory (derivative_step_s). Steps are taken in the
//     Jacobi-scaled eigenbasis of the 7x7 normal matrix, skipping directions below min_condition: a
//     straight, constant-speed drive cannot tell a clock offset from a translation along the road,
//     and then dt does not move.
//   - dt is adopted only when the data pin it down: its standard deviation (cluster-robust
//     sandwich over blocks of time_cluster_frames target frames, see time_sigma) must be
//     below max_time_sigma_s and the
//     estimate must stay within time_window_s of the start; otherwise dt stays at the start and
//     C is re-solved alone (6 parameters) at that dt. time_offset_refined says which happened.
//   - Trust check of the offset (check_time_offset): the 7-parameter solve also runs when dt
//     may not be adopted (the synchronisation found no offset). The offset is trusted when
//     (1) dt's information that a change of C cannot explain, 1 / (H_77 (H^-1)_77) of the
//     joint normal matrix, is at least min_time_observability (a straight drive at constant
//     speed cannot tell an offset from a translation along the road); (2) the fine stage,
//     repeated on the first and on the second half of the target frames (in time) from the
//     whole solve's answer, gives offsets within max_time_disagreement_s of each other; and
//     (3) the offset kept (adopted or the start) is that close to the whole solve's. The
//     cluster-robust sigma sees noise, not bias: on a short drive the joint cost has minima
//     tens of milliseconds off with a sigma of 0.1 ms
//     (docs/experiments/time_offset_drive_length.md). A distrusted
//     offset is reported (time_offset_trusted, time_offset_doubt); it does not change C or dt.
//   - Extrinsic covariance (covariance_6x6, [rho; phi] of C <- exp(xi) C: base frame, m and rad)
//     from the final problem at the answer, by the M-estimator's delete-one-frame jackknife
//     (ulc/core/cluster_covariance.hpp, CR3): sum over target frames c of d_c d_c^T, d_c =
//     (A - A_c)^-1 g_c the estimate's change without frame c, with A = sum psi'(r) J J^T the
//     robust cost's curvature (kernel.curvature: the Geman-McClure kernel of the fine stage
//     turns residuals beyond scale / sqrt(3) away, so A is several times smaller than the IRLS
//     normal matrix sum w J J^T, whose inverse is 3-10x too small in sigma on the simulated
//     drives) and g_c the frame's gradient sum w r J (one frame's points share its placement
//     error: per-point clustering is another 2-4x too small; about 25 frames of a 10 s drive
//     give each a leverage the plain sandwich A^-1 M A^-1 ignores). With dt solved alongside C
//     it is the 7x7 jackknife's 6x6 block, so dt's uncertainty widens C's. Widened for its
//     few frames by Hotelling's T^2 (ulc/core/small_sample.hpp). Measured in
//     docs/experiments/covariance_coverage.md. When dt was adopted and the halves' check ran,
//     the offset's error that every frame shares (a bias the jackknife cannot see) is added as
//     a rank-one term: half the halves' disagreement, one sample of that error, carried into C
//     by dC/ddt = -H_CC^-1 H_Ct (offset_sensitivity). On the 60 s 64-32 drive with a 50 ms
//     offset the jackknife alone left C's 1.9 mm error at e = 2.05, outside its 3-sigma
//     ellipsoid (docs/pipeline.md, "Covariance").
//   - The result keeps C and dt of the input when the registration fails (status says why).
//   - Nothing here throws (a throwing progress hook passes through) or prints; the same results
//     for any number of threads (per-term deterministic reductions summed in term order).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hots/hierarchy.hpp"
#include "hots/options.hpp"
#include "hots/refine_statistics.hpp"
#include "hots/time_sync.hpp"
#include "ulc/core/batched_for.hpp"
#include "ulc/core/cluster_covariance.hpp"
#include "ulc/core/gauss_newton.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/registration_target.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace hots {

namespace sequence_detail {

template <typename S>
using Target = ulc::PlaneCloud<S>;

/// The base's submaps with planes, and each one's anchor frame and time span.
template <typename S>
struct BaseSubmaps {
  std::vector<Target<S>> planes;
  std::vector<std::size_t> anchor;
  std::vector<double> start, end;  ///< a's clock

  /// The submap whose span holds t, else the nearest.
  std::size_t at(double t) const {
    const auto it = std::upper_bound(start.begin(), start.end(), t);
    std::size_t k = it == start.begin() ? 0 : static_cast<std::size_t>(it - start.begin()) - 1;
    if (t > end[k] && k + 1 < start.size() && start[k + 1] - t < t - end[k]) ++k;
    return k;
  }
};

template <typename S>
BaseSubmaps<S> base_submaps(const HierarchyResult<S>& ha,
                            const std::vector<std::vector<ulc::Vec3<S>>>& frames_a,
                            const std::vector<double>& times_a, const SequenceExtrinsicOptions& o) {
  BaseSubmaps<S> out;
  if (ha.members.empty()) return out;
  const std::size_t layer = std::min<std::size_t>(
      static_cast<std::size_t>(std::max(o.target_layer, 0)), ha.members.size() - 1);
  const auto& members = ha.members[layer];
  out.planes.resize(members.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, members.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k != r.end(); ++k) {
                        const auto& m = members[k];
                        const auto& cloud = layer == 0 ? frames_a[m.begin] : m.cloud;
                        auto down = ulc::voxel_downsample(cloud, o.target_voxel);
                        out.planes[k] = Target<S>(down.ok() ? down.cloud.points : cloud, o.planes);
                      }
                    });
  for (const auto& m : members) {
    out.anchor.push_back(m.begin);
    out.start.push_back(times_a[m.begin]);
    out.end.push_back(times_a[m.end - 1]);
  }
  return out;
}

}  // namespace sequence_detail

namespace sequence_detail {

using Vec7 = Eigen::Matrix<double, 7, 1>;
using Mat7 = Eigen::Matrix<double, 7, 7>;
using Mat34 = Eigen::Matrix<double, 3, 4>;

/// What one pass over the matched points sums (7 parameters: [rho; phi; dt]).
struct JointSums {
  Mat7 H = Mat7::Zero();
  Vec7 g = Vec7::Zero();     ///< sum w J r
  std::vector<Vec7> term_g;  ///< g of each term (for time_sigma), filled by the caller
  double cost = 0.0;
  std::size_t count = 0, inliers = 0;
  double inlier_sq = 0.0;
  Vec3d sum_y = Vec3d::Zero();  ///< of the matched points C x, base frame (their centre)
  Mat3d sum_yyT = Mat3d::Zero();

  JointSums& operator+=(const JointSums& o) {
    H += o.H;
    g += o.g;
    sum_y += o.sum_y;
    sum_yyT += o.sum_yyT;
    cost += o.cost;
    count += o.count;
    inliers += o.inliers;
    inlier_sq += o.inlier_sq;
    return *this;
  }
  double rmse() const {
    return inliers ? std::sqrt(inlier_sq / static_cast<double>(inliers)) : 0.0;
  }
};

/// post(t) = T_world_anchor^-1 T_a(t) and its time derivative (central difference).
inline std::pair<Isometry3d, Mat34> placement(const std::vector<double>& times_a,
                                              const std::vector<Isometry3d>& world_a,
                                              const Isometry3d& anchor_inverse, double t,
                                              double h) {
  const Isometry3d post = anchor_inverse * time_sync_detail::pose_at(times_a, world_a, t);
  const Isometry3d plus = anchor_inverse * time_sync_detail::pose_at(times_a, world_a, t + h);
  const Isometry3d minus = anchor_inverse * time_sync_detail::pose_at(times_a, world_a, t - h);
  const Mat34 d = (plus.matrix() - minus.matrix()).topRows<3>() / (2.0 * h);
  return {post, d};
}

/// The point-to-plane residual of x and its Jacobian for C <- exp(xi) C and dt.
inline double joint_residual(const Vec3d& x, const Isometry3d& C, const Isometry3d& post,
                             const Mat34& dpost, const ulc::PlaneMatch& plane, Vec7& J) {
  const Vec3d y = C * x;
  const Vec3d u = post.linear().transpose() * plane.normal;
  J.head<3>() = u;
  J.segment<3>(3) = y.cross(u);
  J(6) = plane.normal.dot(dpost.leftCols<3>() * y + dpost.col(3));
  return plane.normal.dot(post * y - plane.point);
}

/// Step for H d = -g in the Jacobi-scaled eigenbasis, directions below min_condition skipped
/// (the first n parameters only).
inline Vec7 truncated_step(const JointSums& s, int n, double min_condition) {
  Vec7 step = Vec7::Zero();
  const Eigen::MatrixXd H = s.H.topLeftCorner(n, n);
  Eigen::VectorXd scale = H.diagonal().cwiseMax(1e-30).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd Hs = scale.asDiagonal() * H * scale.asDiagonal();
  const Eigen::VectorXd gs = scale.asDiagonal() * s.g.head(n);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Hs);
  const double top = eig.eigenvalues().maxCoeff();
  Eigen::VectorXd ds = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    const double l = eig.eigenvalues()(i);
    if (!(l > min_condition * top)) continue;
    const Eigen::VectorXd v = eig.eigenvectors().col(i);
    ds -= v * (v.dot(gs) / l);
  }
  step.head(n) = scale.asDiagonal() * ds;
  return step;
}

/// Standard deviation of dt by the cluster-robust ("sandwich") covariance
/// H^-1 (sum_c g_c g_c^T) H^-1, g_c = sum of w J r over a cluster of consecutive target frames:
/// points of one frame, and frames close in time, share their errors (a mis-modelled wall, a
/// pose error), so the textbook sigma^2 H^-1 that treats every point as independent is
/// optimistic by an order of magnitude. Infinite when dt is not observable.
inline double time_sigma(const Mat7& H, const std::vector<Vec7>& term_gradients,
                         std::size_t cluster) {
  const Eigen::FullPivLU<Mat7> lu(H);
  if (!lu.isInvertible()) return std::numeric_limits<double>::infinity();
  const Mat7 Hinv = lu.inverse();
  Mat7 meat = Mat7::Zero();
  const std::size_t c = std::max<std::size_t>(cluster, 1);
  for (std::size_t begin = 0; begin < term_gradients.size(); begin += c) {
    Vec7 g = Vec7::Zero();
    for (std::size_t i = begin; i < std::min(begin + c, term_gradients.size()); ++i)
      g += term_gradients[i];
    meat.noalias() += g * g.transpose();
  }
  const double v = (Hinv * meat * Hinv.transpose())(6, 6);
  return v >= 0.0 && std::isfinite(v) ? std::sqrt(v) : std::numeric_limits<double>::infinity();
}

/// 1 / (H_77 (H^-1)_77): dt's information left after C is marginalised, over its own.
inline double time_observability(const Mat7& H) {
  const Eigen::FullPivLU<Mat7> lu(H);
  if (!lu.isInvertible() || !(H(6, 6) > 0.0)) return 0.0;
  const double v = lu.inverse()(6, 6) * H(6, 6);
  return v > 0.0 && std::isfinite(v) ? 1.0 / v : 0.0;
}

}  // namespace sequence_detail

namespace sequence_detail {

/// The whole-sequence residual as gauss_newton.hpp's policy, over b's thinned frames `used`
/// (of which `span` is solved for). State: C and dt; with_time false keeps dt (6 parameters).
template <typename S>
class SequenceProblem {
 public:
  struct State {
    Isometry3d C = Isometry3d::Identity();
    double dt = 0.0;
  };
  using Term = ulc::PointToPlaneTerm<S, Target<S>>;

  SequenceProblem(const BaseSubmaps<S>& submaps, const std::vector<double>& times_a,
                  const std::vector<Isometry3d>& world_a, const std::vector<double>& times_b,
                  std::vector<std::size_t> used, std::vector<std::vector<ulc::Vec3<S>>> sources,
                  double dt0, const SequenceExtrinsicOptions& o)
      : submaps_(submaps),
        times_a_(times_a),
        world_a_(world_a),
        times_b_(times_b),
        used_(std::move(used)),
        sources_(std::move(sources)),
        dt0_(dt0),
        o_(o),
        span_{0, used_.size()} {
    for (const std::size_t a : submaps.anchor) anchor_inverse_.push_back(world_a[a].inverse());
  }

  /// Solve with this stage's gate, kernel and tolerances; 7 parameters or C alone.
  void set_stage(const ulc::RegistrationOptions& stage, bool with_time) {
    stage_ = &stage;
    with_time_ = with_time;
  }
  /// The frames of `used` solved for: [first, last).
  void set_span(std::size_t first, std::size_t last) { span_ = {first, last}; }
  std::size_t frame_count() const { return used_.size(); }
  const std::vector<Term>& terms() const { return terms_; }

  std::size_t match(const State& x) {
    place(x.dt, true);
    return ulc::match_point_to_plane(terms_, x.C, stage_->max_correspondence_distance, matches_);
  }

  bool step(State& x) {
    const JointSums s = sums(x.C);
    const Vec7 delta = truncated_step(s, with_time_ ? 7 : 6, o_.min_condition);
    State next;
    next.C = ulc::se3_exp(ulc::Vec6d(delta.head<6>())) * x.C;
    next.dt =
        std::clamp(x.dt + delta(6), dt0_ - 2.0 * o_.time_window_s, dt0_ + 2.0 * o_.time_window_s);
    const bool small = moved_little_in_c(x.C, next.C) && std::abs(delta(6)) < 1e-6;
    x = next;
    if (with_time_) place(x.dt, false);
    return small;
  }

  bool moved_little(const State& from, const State& to) const {
    return moved_little_in_c(from.C, to.C) && std::abs(to.dt - from.dt) < 1e-6;
  }

  /// The sums at x with fresh matches (stage's gate): the solve's final statistics.
  JointSums final_sums(const State& x) {
    match(x);
    return sums(x.C);
  }

  /// Every matched point of the current matches at C: visit(frame k of `used`, J, r) in term
  /// and point order.
  template <class Visit>
  void visit_points(const Isometry3d& C, Visit&& visit) const {
    Vec7 J;
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      const Term& term = terms_[i];
      if (matches_[i].size() != term.size) continue;
      for (std::size_t p = 0; p < term.size; ++p) {
        const ulc::PlaneMatch& plane = matches_[i][p];
        if (plane.normal.squaredNorm() == 0.0) continue;
        const double r = joint_residual(term.points[p].template cast<double>(), C, term.post,
                                        dposts_[i], plane, J);
        visit(term_frame_[i], J, r);
      }
    }
  }

 private:
  bool moved_little_in_c(const Isometry3d& from, const Isometry3d& to) const {
    return (to.translation() - from.translation()).norm() < stage_->translation_tolerance &&
           ulc::so3_log(to.linear() * from.linear().transpose()).norm() <
               stage_->rotation_tolerance;
  }

  /// Terms at dt; the submaps are chosen afresh only when choose_submaps.
  void place(double dt, bool choose_submaps) {
    if (choose_submaps) choose(dt);
    dposts_.resize(terms_.size());
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      const double t = times_b_[used_[term_frame_[i]]] + dt;
      std::tie(terms_[i].post, dposts_[i]) =
          placement(times_a_, world_a_, anchor_inverse_[term_submap_[i]], t, o_.derivative_step_s);
    }
  }

  /// One term per frame of the span whose instant t_j + dt falls in a's span: its points
  /// against the submap that holds that instant.
  void choose(double dt) {
    terms_.clear();
    term_frame_.clear();
    term_submap_.clear();
    for (std::size_t k = span_.first; k < span_.second; ++k) {
      const double t = times_b_[used_[k]] + dt;
      if (t < times_a_.front() || t > times_a_.back() || sources_[k].empty()) continue;
      const std::size_t m = submaps_.at(t);
      if (submaps_.planes[m].empty()) continue;
      Term term;
      term.points = sources_[k].data();
      term.size = sources_[k].size();
      term.target = &submaps_.planes[m];
      terms_.push_back(term);
      term_frame_.push_back(k);
      term_submap_.push_back(m);
    }
  }

  /// The normal equations at C on the current matches, per term (for time_sigma) and summed.
  JointSums sums(const Isometry3d& C) const {
    JointSums total;
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      if (matches_[i].size() != terms_[i].size) continue;
      const JointSums term_sums = term_sums_at(i, C);
      total += term_sums;
      total.term_g.push_back(term_sums.g);
    }
    return total;
  }

  JointSums term_sums_at(std::size_t i, const Isometry3d& C) const {
    const Term& term = terms_[i];
    const auto& planes = matches_[i];
    const ulc::RegistrationOptions& stage = *stage_;
    const auto body = [&](std::size_t begin, std::size_t end, JointSums acc) {
      Vec7 J;
      for (std::size_t p = begin; p < end; ++p) {
        if (planes[p].normal.squaredNorm() == 0.0) continue;
        const Vec3d x = term.points[p].template cast<double>();
        const double r = joint_residual(x, C, term.post, dposts_[i], planes[p], J);
        const double w = stage.kernel.weight(r);
        const Vec3d y = C * x;
        acc.sum_y += y;
        acc.sum_yyT += y * y.transpose();
        acc.H.noalias() += w * J * J.transpose();
        acc.g.noalias() += (w * r) * J;
        acc.cost += stage.kernel.rho(r);
        ++acc.count;
        if (std::abs(r) <= stage.inlier_distance) {
          ++acc.inliers;
          acc.inlier_sq += r * r;
        }
      }
      return acc;
    };
    const auto join = [](JointSums a, const JointSums& b) {
      a += b;
      return a;
    };
    return ulc::deterministic_reduce(term.size, JointSums{}, body, join, stage.grain);
  }

  const BaseSubmaps<S>& submaps_;
  const std::vector<double>& times_a_;
  const std::vector<Isometry3d>& world_a_;
  const std::vector<double>& times_b_;
  std::vector<Isometry3d> anchor_inverse_;
  std::vector<std::size_t> used_;                   ///< b's frames taken (frame_stride)
  std::vector<std::vector<ulc::Vec3<S>>> sources_;  ///< their thinned points
  double dt0_;
  const SequenceExtrinsicOptions& o_;
  std::pair<std::size_t, std::size_t> span_;
  const ulc::RegistrationOptions* stage_ = nullptr;
  bool with_time_ = true;
  std::vector<Term> terms_;
  std::vector<std::size_t> term_frame_, term_submap_;  ///< per term: index into used_, submap
  std::vector<Mat34> dposts_;
  ulc::PointToPlaneMatches matches_;
};

/// The stride through b's frames: frame_stride, shortened while it would keep fewer than
/// min_frames of them.
inline std::size_t target_stride(std::size_t frames, const SequenceExtrinsicOptions& o) {
  std::size_t stride = std::max<std::size_t>(o.frame_stride, 1);
  while (stride > 1 && (frames + stride - 1) / stride < o.min_frames) --stride;
  return stride;
}

/// Every target_stride-th frame of b, thinned at source_voxel once: their placement depends on
/// dt only.
template <typename S>
SequenceProblem<S> sequence_problem(const BaseSubmaps<S>& submaps,
                                    const std::vector<double>& times_a,
                                    const std::vector<Isometry3d>& world_a,
                                    const std::vector<std::vector<ulc::Vec3<S>>>& frames_b,
                                    const std::vector<double>& times_b, double dt0,
                                    const SequenceExtrinsicOptions& o) {
  std::vector<std::size_t> used;
  const std::size_t stride = target_stride(frames_b.size(), o);
  for (std::size_t j = 0; j < frames_b.size(); j += stride) used.push_back(j);
  std::vector<std::vector<ulc::Vec3<S>>> sources(used.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, used.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k != r.end(); ++k) {
                        const auto& f = frames_b[used[k]];
                        auto down = ulc::voxel_downsample(f, o.source_voxel);
                        sources[k] = down.ok() && o.source_voxel > 0.0 ? down.cloud.points : f;
                      }
                    });
  return SequenceProblem<S>(submaps, times_a, world_a, times_b, std::move(used), std::move(sources),
                            dt0, o);
}

/// One solve over the stages (fine_only: the last stage alone, for a start already at a
/// solution), with its final sums at fresh matches.
struct Solve {
  bool ok = false;
  const char* reason = "";
  Isometry3d C = Isometry3d::Identity();
  double dt = 0.0;
  JointSums sums;
  std::size_t frames = 0, source_points = 0;  ///< the terms the final sums ran over
};

template <typename S>
Solve solve(SequenceProblem<S>& problem, const Isometry3d& C, double dt, bool with_time,
            const SequenceExtrinsicOptions& o, int& iterations, bool fine_only = false) {
  constexpr const char* kStarved =
      "too few correspondences between the target frames and the base's submaps";
  Solve out;
  typename SequenceProblem<S>::State x{C, dt};
  for (std::size_t st = fine_only ? o.stages.size() - 1 : 0; st < o.stages.size(); ++st) {
    const auto& stage = o.stages[st];
    problem.set_stage(stage, with_time);
    const ulc::GaussNewtonRun run = ulc::gauss_newton(
        problem, x, {stage.max_iterations, stage.max_solver_iterations, stage.min_correspondences});
    iterations += run.iterations;
    if (run.starved) {
      out.reason = kStarved;
      return out;
    }
  }
  problem.set_stage(o.stages.back(), with_time);
  out.sums = problem.final_sums(x);
  out.frames = problem.terms().size();
  for (const auto& t : problem.terms()) out.source_points += t.size;
  if (out.sums.count < o.stages.back().min_correspondences) {
    out.reason = kStarved;
    return out;
  }
  out.ok = true;
  out.C = x.C;
  out.dt = x.dt;
  return out;
}

/// Why the whole-sequence step cannot run; nullptr when it can.
template <typename S>
const char* input_problem(const std::vector<std::vector<ulc::Vec3<S>>>& frames_a,
                          const std::vector<double>& times_a,
                          const std::vector<Isometry3d>& world_a,
                          const std::vector<std::vector<ulc::Vec3<S>>>& frames_b,
                          const std::vector<double>& times_b, double dt0,
                          const SequenceExtrinsicOptions& o) {
  if (times_a.size() < 2 || world_a.size() != times_a.size() || frames_a.size() != times_a.size() ||
      frames_b.size() != times_b.size() || o.stages.empty() || !(o.source_voxel >= 0.0) ||
      !(o.target_voxel >= 0.0) || !(o.time_window_s >= 0.0) || !(o.derivative_step_s > 0.0) ||
      !(o.min_condition >= 0.0) || !(o.max_time_disagreement_s >= 0.0) ||
      !(o.min_time_observability >= 0.0) || !std::isfinite(dt0))
    return "bad inputs or options";
  for (const auto& stage : o.stages)
    if (stage.max_iterations < 1 || stage.max_solver_iterations < 1 ||
        !(stage.max_correspondence_distance > 0.0) || stage.grain < 1)
      return "bad registration stage";
  return nullptr;
}

/// dC/ddt = -H_CC^-1 H_Ct from the joint normal matrix at the answer (see
/// SequenceExtrinsicResult::offset_sensitivity); zero when H_CC cannot be inverted.
inline Vec6d offset_sensitivity(const Mat7& H) {
  const Eigen::LDLT<Mat6d> ldlt(H.topLeftCorner<6, 6>());
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return Vec6d::Zero();
  const Vec6d sensitivity = -ldlt.solve(H.topRightCorner<6, 1>());
  return sensitivity.allFinite() ? sensitivity : Vec6d::Zero();
}

/// The offset's shared error carried into C (see the conventions): zero unless dt was adopted
/// and the halves' check ran.
inline Mat6d offset_error_term(const SequenceExtrinsicResult& result) {
  if (!result.time_offset_refined || !result.time_offset_checked) return Mat6d::Zero();
  const double spread = 0.5 * (result.half_time_offset_s[0] - result.half_time_offset_s[1]);
  const Vec6d moved = result.offset_sensitivity * spread;
  return moved * moved.transpose();
}

/// The joint solve's dt statistics, and whether dt is adopted.
inline void judge_joint_offset(const Solve& s, double dt0, const SequenceExtrinsicOptions& o,
                               SequenceExtrinsicResult& result) {
  result.joint_time_offset_s = s.dt;
  result.offset_sensitivity = offset_sensitivity(s.sums.H);
  result.time_sigma_s = time_sigma(s.sums.H, s.sums.term_g, o.time_cluster_frames);
  result.time_observability = time_observability(s.sums.H);
  result.time_offset_refined = o.estimate_time_offset && result.time_sigma_s < o.max_time_sigma_s &&
                               std::abs(s.dt - dt0) <= o.time_window_s;
}

/// The trust check of the offset (see the conventions): observability, the two halves'
/// agreement, and the kept offset against the joint solve's. Fills time_offset_doubt.
template <typename S>
void check_offset(SequenceProblem<S>& problem, const Solve& s, double dt0,
                  const SequenceExtrinsicOptions& o, SequenceExtrinsicResult& result) {
  result.time_offset_checked = true;
  const double kept = result.time_offset_refined ? s.dt : dt0;
  if (result.time_observability < o.min_time_observability) {
    result.time_offset_doubt =
        "the drive does not pin the clock offset down: it is nearly interchangeable with a "
        "translation along the road";
  } else {
    // Each half from the whole solve's answer (fine stage only); a half that cannot be
    // registered on its own fails the check.
    bool halves_ok = true;
    const std::size_t n = problem.frame_count(), middle = n / 2;
    for (int h = 0; h < 2; ++h) {
      problem.set_span(h == 0 ? 0 : middle, h == 0 ? middle : n);
      const Solve half = solve(problem, s.C, s.dt, true, o, result.iterations, true);
      halves_ok = halves_ok && half.ok;
      result.half_time_offset_s[h] = half.ok ? half.dt : s.dt;
    }
    problem.set_span(0, n);
    if (!halves_ok)
      result.time_offset_doubt = "a half of the drive could not be registered on its own";
    else if (std::abs(result.half_time_offset_s[0] - result.half_time_offset_s[1]) >
             o.max_time_disagreement_s)
      result.time_offset_doubt = "the two halves of the drive give different clock offsets";
    else if (std::abs(kept - s.dt) > o.max_time_disagreement_s)
      result.time_offset_doubt =
          "the registration of the whole drive points to a different clock offset than the "
          "time synchronisation's";
  }
  result.time_offset_trusted = *result.time_offset_doubt == '\0';
}

/// The covariance of C from the final problem at the solve's answer (see extrinsic covariance
/// in the header comment): the delete-one-frame jackknife of the M-estimator
/// (ulc/core/cluster_covariance.hpp), with each point's curvature psi'(r) J J^T and gradient
/// w r J clustered by target frame. With dt solved alongside C (7 parameters) it is the 7x7
/// jackknife's 6x6 block (C's marginal); with dt held, the 6x6 problem's. Empty when fewer than
/// two frames matched or leaving one frame out makes the problem singular.
template <typename S>
std::optional<Mat6d> extrinsic_covariance(SequenceProblem<S>& problem, const Solve& s,
                                          bool with_time, const SequenceExtrinsicOptions& o) {
  const ulc::RegistrationOptions& stage = o.stages.back();
  problem.set_stage(stage, with_time);
  problem.match({s.C, s.dt});
  ulc::ClusterJackknife<7, std::size_t> frames;
  problem.visit_points(s.C, [&](std::size_t frame, const Vec7& J, double r) {
    frames.add(frame, Mat7(stage.kernel.curvature(r) * J * J.transpose()),
               Vec7((stage.kernel.weight(r) * r) * J));
  });
  // With dt: C's marginal of the 7x7 estimate, widened as a 6-dimensional T^2 with the same
  // G - 1 degrees of freedom.
  return with_time ? frames.widened_marginal<6, 7>() : frames.widened_covariance<6>();
}

/// The solve's answer and statistics into the result.
inline void take_solve(const Solve& s, SequenceExtrinsicResult& result) {
  result.status = SequenceExtrinsicStatus::ok;
  result.extrinsic = s.C;
  result.time_offset_s = s.dt;
  result.frames = s.frames;
  result.source_points = s.source_points;
  result.correspondences = s.sums.count;
  result.inliers = s.sums.inliers;
  result.rmse = s.sums.rmse();
  result.cost = s.sums.cost;
  result.information = s.sums.H.topLeftCorner<6, 6>();
  if (s.sums.count > 0) {
    const double n = static_cast<double>(s.sums.count);
    result.centre = s.sums.sum_y / n;
    result.covariance = s.sums.sum_yyT / n - result.centre * result.centre.transpose();
  }
}

}  // namespace sequence_detail

/// The whole-sequence step over one base trajectory and one starting offset dt0, prepared once
/// (the base's submaps with their planes, b's thinned frames: most of a solve's cost) and
/// solved from one or more starts C0. world_a: T_world_a after the pose graph; frames_b: b's
/// prepared (deskewed, downsampled) frames in b's body frame at times_b. The inputs must
/// outlive it.
template <typename S>
class SequenceStep {
 public:
  /// progress (optional) gets 1/6 after the submaps and 2/6 after the frames (solve's six
  /// sub-steps continue it).
  SequenceStep(const HierarchyResult<S>& ha, const std::vector<std::vector<ulc::Vec3<S>>>& frames_a,
               const std::vector<double>& times_a, const std::vector<Isometry3d>& world_a,
               const std::vector<std::vector<ulc::Vec3<S>>>& frames_b,
               const std::vector<double>& times_b, double dt0,
               const SequenceExtrinsicOptions& o = {}, const ulc::StepProgress& progress = {})
      : o_(o), dt0_(dt0) {
    namespace d = sequence_detail;
    if (!o.enabled) return;
    input_error_ = d::input_problem(frames_a, times_a, world_a, frames_b, times_b, dt0, o);
    if (input_error_) return;
    submaps_ = d::base_submaps(ha, frames_a, times_a, o);
    if (submaps_.planes.empty()) {
      input_error_ = "no submaps";
      return;
    }
    if (progress) progress(1.0 / 6.0);
    problem_.emplace(d::sequence_problem(submaps_, times_a, world_a, frames_b, times_b, dt0, o_));
    if (progress) progress(2.0 / 6.0);
  }
  SequenceStep(const SequenceStep&) = delete;
  SequenceStep& operator=(const SequenceStep&) = delete;

  /// See the header comment. progress (optional) gets 3/6 .. 6/6 after the solve, the offset
  /// check, the solve without the offset and the covariance.
  SequenceExtrinsicResult solve(const Isometry3d& C0, const ulc::StepProgress& progress = {}) {
    return run(C0, progress);
  }

  /// The extrinsic alone from another start, solved the way solve() ended: with the clock offset
  /// free from the step's start dt0 when solve() adopted a refined offset
  /// (`time_offset_refined`), held at dt0 otherwise. That solve is the one solve() would end on
  /// from C0 (to the bit when its offset judgement agrees), without the joint solve it judges
  /// the offset by, the offset's trust check and the covariance: what a second start is asked
  /// for, where it ends (60 s 64-32 drive: about 1.5 s of the step's 7.9 s with the rerun).
  SequenceExtrinsicResult solve_extrinsic(const Isometry3d& C0, bool time_offset_refined) {
    SequenceExtrinsicResult result = started(C0);
    if (result.status != SequenceExtrinsicStatus::ok) return result;
    const sequence_detail::Solve s =
        sequence_detail::solve(*problem_, C0, dt0_, time_offset_refined, o_, result.iterations);
    if (!s.ok) return failed(C0, SequenceExtrinsicStatus::registration_failed, s.reason, result);
    sequence_detail::take_solve(s, result);
    result.time_offset_refined = time_offset_refined;
    return result;
  }

 private:
  /// A result at the start; status invalid_input when no solve can run from C0, disabled when
  /// the step is.
  SequenceExtrinsicResult started(const Isometry3d& C0) const {
    SequenceExtrinsicResult result;
    result.extrinsic = C0;
    result.time_offset_s = result.joint_time_offset_s = dt0_;
    if (!o_.enabled) return result;
    if (!C0.matrix().allFinite())
      return failed(C0, SequenceExtrinsicStatus::invalid_input, "the start extrinsic is not finite",
                    result);
    if (input_error_)
      return failed(C0, SequenceExtrinsicStatus::invalid_input, input_error_, result);
    result.status = SequenceExtrinsicStatus::ok;
    result.targets = submaps_.planes.size();
    return result;
  }

  /// result failed with `status` and `why`, back at the start.
  SequenceExtrinsicResult failed(const Isometry3d& C0, SequenceExtrinsicStatus status,
                                 const char* why, SequenceExtrinsicResult result) const {
    result.status = status;
    result.reason = why;
    result.extrinsic = C0;
    result.time_offset_s = dt0_;
    return result;
  }

  SequenceExtrinsicResult run(const Isometry3d& C0, const ulc::StepProgress& progress) {
    namespace d = sequence_detail;
    auto done = [&progress](int sub_steps) {
      if (progress) progress(sub_steps / 6.0);
    };
    SequenceExtrinsicResult result = started(C0);
    if (result.status != SequenceExtrinsicStatus::ok) return result;
    auto fail = [&](const char* why) {
      return failed(C0, SequenceExtrinsicStatus::registration_failed, why, result);
    };
    auto& problem = *problem_;
    const bool joint = o_.estimate_time_offset || o_.check_time_offset;
    d::Solve s = d::solve(problem, C0, dt0_, joint, o_, result.iterations);
    if (!s.ok) return fail(s.reason);
    if (joint) d::judge_joint_offset(s, dt0_, o_, result);
    done(3);
    if (o_.check_time_offset) d::check_offset(problem, s, dt0_, o_, result);
    done(4);
    if (joint && !result.time_offset_refined) {
      s = d::solve(problem, C0, dt0_, false, o_, result.iterations);
      if (!s.ok) return fail(s.reason);
    }
    done(5);
    d::take_solve(s, result);
    if (const auto c =
            d::extrinsic_covariance(problem, s, joint && result.time_offset_refined, o_)) {
      result.covariance_6x6 = *c + d::offset_error_term(result);
      result.has_covariance = true;
    }
    done(6);
    return result;
  }

  SequenceExtrinsicOptions o_;
  double dt0_ = 0.0;
  const char* input_error_ = nullptr;  ///< why no solve can run; nullptr when one can
  sequence_detail::BaseSubmaps<S> submaps_;
  std::optional<sequence_detail::SequenceProblem<S>> problem_;  ///< reads submaps_ and o_
};

/// See the header comment: SequenceStep's solve from C0, for a single start. progress
/// (optional) is called on the calling thread after each of its six sub-steps (submaps,
/// problem, solve, offset check, solve without the offset, covariance), as equal fractions.
template <typename S>
SequenceExtrinsicResult sequence_extrinsic(const HierarchyResult<S>& ha,
                                           const std::vector<std::vector<ulc::Vec3<S>>>& frames_a,
                                           const std::vector<double>& times_a,
                                           const std::vector<Isometry3d>& world_a,
                                           const std::vector<std::vector<ulc::Vec3<S>>>& frames_b,
                                           const std::vector<double>& times_b, const Isometry3d& C0,
                                           double dt0, const SequenceExtrinsicOptions& o = {},
                                           const ulc::StepProgress& progress = {}) {
  SequenceStep<S> step(ha, frames_a, times_a, world_a, frames_b, times_b, dt0, o, progress);
  return step.solve(C0, progress);
}

}  // namespace hots
