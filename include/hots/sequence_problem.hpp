// The whole-sequence step's problem (sequence_extrinsic.hpp) as gauss_newton.hpp's residual
// policy over b's thinned frames, and one solve of it over the registration stages.
//
// Conventions this header owns:
//   - C and dt are solved together by Gauss-Newton on the 7 parameters [rho; phi; dt]
//     (gauss_newton.hpp's loop with SequenceProblem as its residual: robust IRLS weights,
//     matches refreshed every iteration, stages coarse to fine as in point_to_plane.hpp). The
//     residual's dt column is n . (d post / d dt) y, y = C x, with d post / d dt by a central
//     difference of the interpolated trajectory (derivative_step_s). Steps are taken in the
//     Jacobi-scaled eigenbasis of the 7x7 normal matrix, skipping directions below min_condition: a
//     straight, constant-speed drive cannot tell a clock offset from a translation along the road,
//     and then dt does not move.
//   - The frames solved for can be narrowed to a span of them (set_span): the offset's trust
//     check solves each half of the drive alone (sequence_offset.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <tuple>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hots/options.hpp"
#include "hots/sequence_terms.hpp"
#include "ulc/core/gauss_newton.hpp"
#include "ulc/core/parallel_reduce.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace hots {

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

}  // namespace sequence_detail
}  // namespace hots
