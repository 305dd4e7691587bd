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
// The problem and its solve are sequence_problem.hpp (built from sequence_terms.hpp); the clock
// offset's adoption, trust check and shared error are sequence_offset.hpp.
//
// Conventions this header owns:
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

#include <optional>
#include <vector>

#include "hots/hierarchy.hpp"
#include "hots/options.hpp"
#include "hots/refine_statistics.hpp"
#include "hots/sequence_offset.hpp"
#include "hots/sequence_problem.hpp"
#include "hots/sequence_terms.hpp"
#include "ulc/core/batched_for.hpp"
#include "ulc/core/cluster_covariance.hpp"
#include "ulc/core/types.hpp"

namespace hots {

namespace sequence_detail {

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
