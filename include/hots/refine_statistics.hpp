// The results of hots::refine (hots.hpp) that a caller keeps: RefineResult, its status
// (RefineStatus, to_string) and statistics (RefineStatistics), and the whole-sequence step's
// result they hold (SequenceExtrinsicResult, sequence_extrinsic.hpp).
//
// Separate from the algorithms' headers so that a file that only holds or reports these
// results (ulc::PairCalibration's HotsReport) includes this light header, which needs only the
// standard library, Eigen/Core and Eigen/Geometry, instead of the stages' inline functions, TBB
// and Eigen's solvers (docs/design.md). hots.hpp and sequence_extrinsic.hpp include it; the
// fields are documented with the algorithms that fill them.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "ulc/core/types.hpp"

namespace hots {

using ulc::Isometry3d;
using ulc::Mat6d;
using ulc::Vec6d;

enum class SequenceExtrinsicStatus { ok, disabled, invalid_input, registration_failed };

inline const char* to_string(SequenceExtrinsicStatus s) {
  switch (s) {
    case SequenceExtrinsicStatus::ok:
      return "ok";
    case SequenceExtrinsicStatus::disabled:
      return "disabled";
    case SequenceExtrinsicStatus::invalid_input:
      return "invalid_input";
    default:
      return "registration_failed";
  }
}

struct SequenceExtrinsicResult {
  SequenceExtrinsicStatus status = SequenceExtrinsicStatus::disabled;
  const char* reason = "";
  Isometry3d extrinsic = Isometry3d::Identity();
  double time_offset_s = 0.0;
  bool time_offset_refined = false;    ///< dt was pinned down and adopted
  double joint_time_offset_s = 0.0;    ///< the 7-parameter solve's dt (adopted or not)
  double time_sigma_s = 0.0;           ///< its marginal standard deviation (inf: unobservable)
  bool time_offset_checked = false;    ///< the halves' trust check ran
  bool time_offset_trusted = true;     ///< it passed (true when it did not run)
  const char* time_offset_doubt = "";  ///< why not, one sentence
  double half_time_offset_s[2] = {0.0, 0.0};  ///< the first and the second half's dt
  /// dC/ddt at the joint solve's answer, -H_CC^-1 H_Ct ([rho; phi] per second): how far C
  /// moves for an error of the offset; zero when the joint solve did not run or H_CC is
  /// singular.
  Vec6d offset_sensitivity = Vec6d::Zero();
  /// 1 / (H_77 (H^-1)_77) of the joint normal matrix: the share of dt's information that a
  /// change of C cannot explain (1: independent of C, 0: a translation along the road would do).
  double time_observability = 0.0;
  /// The final solve's information for C at its dt (the joint normal matrix's 6x6 block: a
  /// left perturbation of C in the base frame, robust weights), the matched target points'
  /// centroid and covariance in the base frame (m, m^2): what ulc/core/observability.hpp
  /// judges.
  /// The geometry alone: whether dt can be told from a translation is time_observability's
  /// question (with dt marginalised, 10 s town drives fell to 0.003-0.012, as low as the
  /// tunnel: docs/experiments/degenerate_scenes.md).
  Mat6d information = Mat6d::Zero();
  ulc::Vec3d centre = ulc::Vec3d::Zero();
  ulc::Mat3d covariance = ulc::Mat3d::Zero();
  std::size_t frames = 0, targets = 0, source_points = 0;
  std::size_t correspondences = 0, inliers = 0;
  double rmse = 0.0;   ///< m, inliers at the result
  double cost = 0.0;   ///< final robust cost at the result
  int iterations = 0;  ///< matchings, all solves and stages
  /// Covariance of C ([rho; phi], left, base frame; m and rad) from the final problem
  /// (sequence_extrinsic.hpp, extrinsic_covariance); zero when none could be formed.
  Mat6d covariance_6x6 = Mat6d::Zero();
  bool has_covariance = false;

  bool ok() const { return status == SequenceExtrinsicStatus::ok; }
};

enum class RefineStatus {
  ok,
  invalid_input,
  graph_failed,
  time_sync_failed,
  sequence_failed,
  time_offset_untrusted,  ///< the drive does not pin the clock offset down (see reason)
  extrinsic_unconfirmed   ///< too few cross links: the LiDARs' views do not confirm C
};

inline const char* to_string(RefineStatus s) {
  switch (s) {
    case RefineStatus::ok:
      return "ok";
    case RefineStatus::invalid_input:
      return "invalid_input";
    case RefineStatus::graph_failed:
      return "graph_failed";
    case RefineStatus::sequence_failed:
      return "sequence_failed";
    case RefineStatus::time_offset_untrusted:
      return "time_offset_untrusted";
    case RefineStatus::extrinsic_unconfirmed:
      return "extrinsic_unconfirmed";
    default:
      return "time_sync_failed";
  }
}

/// What the cross links said of the extrinsic HOTS started from (refine_steps.hpp,
/// judge_links): enough kept links agree; too few do; or none was kept, too little overlap to
/// judge. not_judged: the rule is off or no link was tried.
enum class LinkVerdict { not_judged, kept_links_agree, kept_links_refute, too_little_overlap };

inline const char* to_string(LinkVerdict v) {
  switch (v) {
    case LinkVerdict::kept_links_agree:
      return "kept_links_agree";
    case LinkVerdict::kept_links_refute:
      return "kept_links_refute";
    case LinkVerdict::too_little_overlap:
      return "too_little_overlap";
    default:
      return "not_judged";
  }
}

inline bool confirms(LinkVerdict v) {
  return v == LinkVerdict::not_judged || v == LinkVerdict::kept_links_agree;
}

/// One cross-link registration as HOTS tried it (cross_links.hpp): its layer, whether it
/// converged, its inlier ratio (over all of b's points, and over those within a's reach) and
/// how far it moved from its start. It was kept when it converged with the ratio the links were
/// judged by >= CrossLinkOptions::min_inlier_ratio, and agreed when it moved less than the
/// agree bounds.
struct CrossLinkRecord {
  int layer = 0;
  bool converged = false;
  double inlier_ratio = 0.0, moved_rad = 0.0, moved_m = 0.0;
  double inlier_ratio_in_reach = 0.0;
};

struct RefineStatistics {
  std::size_t windows = 0, failed_windows = 0, planes = 0;
  std::size_t ba_factors = 0, cross_links = 0, cross_links_attempted = 0, extrinsic_ties = 0;
  std::size_t cross_links_agreeing = 0;  ///< kept links that confirm the start (cross_links.hpp)
  /// Cross-link registrations that converged, kept or not, and their median inlier ratio; the
  /// weak links and those of them that agree (CrossLinkStats).
  std::size_t cross_links_converged = 0, cross_links_weak = 0, cross_links_weak_agreeing = 0;
  double cross_link_inlier_ratio_median = 0.0;
  LinkVerdict link_verdict = LinkVerdict::not_judged;  ///< the trust rule on the cross links
  /// The links were kept and judged by their inlier ratio within a's reach (the second look of
  /// refine_steps.hpp); the counts above are then that look's.
  bool links_judged_within_reach = false;
  std::vector<CrossLinkRecord> cross_link_records;  ///< every registration, in link order
  std::size_t boundary_factors = 0;  ///< top-layer submap boundaries tied in the graph
  std::size_t boundary_links = 0;    ///< of those, by registering the submaps (the rest: odometry)
  std::size_t boundary_bridges = 0;  ///< boundaries tied by a bridge BA (not in boundary_factors)
  bool prepared_a_reused = false;    ///< a's preparation came from the caller (refine's prepared_a)
  double graph_initial_cost = 0.0, graph_cost = 0.0;
  int graph_iterations = 0;
  double time_sync_spread = 0.0;
  std::size_t time_sync_pairs = 0;
  Isometry3d graph_extrinsic = Isometry3d::Identity();  ///< C as the pose graph left it
  Isometry3d sync_extrinsic = Isometry3d::Identity();   ///< C of the time synchronisation
  double sync_time_offset_s = 0.0;                      ///< dt of the time synchronisation
  bool sync_significant = false;                        ///< its minimum passed the test
  SequenceExtrinsicResult sequence;                     ///< the last step (status disabled: off)
  /// The step rerun from refine's start (refine_steps.hpp, rerun_from_start; disabled: not run).
  SequenceExtrinsicResult sequence_rerun;
  double sequence_seconds = 0.0;  ///< its wall time (statistics only)
  /// Wall time of each phase, s (statistics only: where the stage spends its time).
  double prepare_seconds = 0.0, hierarchy_seconds = 0.0, links_seconds = 0.0;
  double graph_seconds = 0.0, sync_seconds = 0.0;
};

struct RefineResult {
  RefineStatus status = RefineStatus::ok;
  const char* reason = "";
  Isometry3d extrinsic = Isometry3d::Identity();  ///< T_base_target
  double time_offset_s = 0.0;
  Mat6d covariance_6x6 = Mat6d::Zero();
  std::vector<Isometry3d> poses_a;  ///< T_mapa_a, refined
  std::vector<Isometry3d> poses_b;  ///< T_mapb_b, refined
  RefineStatistics statistics;
  std::vector<std::pair<double, double>> spread_curve;  ///< (offset, spread), last pass

  bool ok() const { return status == RefineStatus::ok; }
};

}  // namespace hots
