// The clock offset in the whole-sequence step (sequence_extrinsic.hpp): whether the joint solve's
// dt is adopted, whether it can be trusted, and the error of it that every frame shares, carried
// into the extrinsic's covariance.
//
// Conventions this header owns:
//   - dt is adopted only when the data pin it down: its standard deviation (cluster-robust
//     sandwich over blocks of time_cluster_frames target frames, see time_sigma) must be below
//     max_time_sigma_s and the estimate must stay within time_window_s of the start; otherwise
//     dt stays at the start and C is re-solved alone (6 parameters) at that dt.
//     time_offset_refined says which happened (judge_joint_offset).
//   - Trust check of the offset (check_time_offset; check_offset): the 7-parameter solve also
//     runs when dt may not be adopted (the synchronisation found no offset). The offset is
//     trusted when (1) dt's information that a change of C cannot explain, 1 / (H_77 (H^-1)_77)
//     of the joint normal matrix, is at least min_time_observability (a straight drive at
//     constant speed cannot tell an offset from a translation along the road); (2) the fine
//     stage, repeated on the first and on the second half of the target frames (in time) from
//     the whole solve's answer, gives offsets within max_time_disagreement_s of each other; and
//     (3) the offset kept (adopted or the start) is that close to the whole solve's. The
//     cluster-robust sigma sees noise, not bias: on a short drive the joint cost has minima
//     tens of milliseconds off with a sigma of 0.1 ms
//     (docs/experiments/time_offset_drive_length.md). A distrusted offset is reported
//     (time_offset_trusted, time_offset_doubt); it does not change C or dt.
#pragma once

#include <cmath>

#include <Eigen/Cholesky>

#include "hots/options.hpp"
#include "hots/refine_statistics.hpp"
#include "hots/sequence_problem.hpp"
#include "ulc/core/types.hpp"

namespace hots {
namespace sequence_detail {

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

}  // namespace sequence_detail
}  // namespace hots
