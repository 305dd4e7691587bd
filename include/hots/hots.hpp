// HOTS: hierarchical optimisation and time synchronisation, the last stages of the paper
// (Sec. "Pose Refinement by Hierarchical Optimization" and "Time Synchronization"):
//   frames + odometry poses of LiDARs a (base) and b (target) + an extrinsic
//   -> deskewed, downsampled frames -> one hierarchy per LiDAR (hierarchy.hpp)
//   -> cross-LiDAR links (cross_links.hpp) -> one pose graph with the extrinsic as a variable,
//      solved by our sparse LM (pose_graph.hpp, sparse_lm.hpp)
//   -> time synchronisation on the refined poses (time_sync.hpp)
//   -> every target frame against the base's submaps through the base's refined trajectory
//      (sequence_extrinsic.hpp) -> extrinsic, clock offset.
//
// Conventions this header owns:
//   - Inputs: two LidarSequences (ulc/core/lidar_sequence.hpp): frames (random-access containers
//     of traits clouds, points in the LiDAR frame at
//     each point's own time, per-point times relative to the frame timestamp when the cloud has
//     them), timestamps (own clocks), poses_a = T_mapa_a and poses_b = T_mapb_b at the frame
//     timestamps, each LiDAR in its own map frame (as jeep's odometry gives them), and the
//     extrinsic C = T_base_target. Clock offset: t_a = t_b + time_offset_s (docs/design.md).
//   - The two maps are put in one world (map a) by T_mapa_mapb = P_a(t_a0) C P_b(t_a0)^-1 at
//     a's first frame, b's pose interpolated to that instant (identity-free for jeep's
//     odometry, whose map b is b's frame at a's first instant: T_mapa_mapb = C).
//   - Frames are deskewed with the motion between their pose and the next frame's (constant
//     velocity), then voxel-downsampled (frame_voxel). With hierarchy.sweep_parts > 1 each
//     frame's points are also split by time into that many parts, and the hierarchy's layer 0
//     treats every frame as a sweep between its pose and the next frame's (sweep_ba.hpp).
//   - Pose graph: one variable per frame of a and b (T_world_frame) and one for C; a's first
//     frame is the gauge. Factors: every window's BA (information from its Hessian), every
//     cross link (Huber), each boundary between two top-layer submaps (no window spans it:
//     without a factor each top submap would float on its own, held only by the damping): a
//     bridge BA over the members on both sides (boundary_bridges.hpp, with boundary_bridges),
//     else the two submaps registered to each other (boundary_links.hpp), else the odometry's
//     step across it, and for every b frame an extrinsic tie to the a frame nearest its
//     instant, with a's motion to that instant taken from the current poses:
//     r = log((T_a L)^-1 T_b C^-1) (isotropic information, extrinsic_sigma_*). The ties know the
//     clock offset only through the current estimate, so they are deliberately weak: the
//     offset itself comes from the time synchronisation, and a second pass (passes = 2)
//     rebuilds the ties with it.
//   - Result extrinsic and offset = the whole-sequence step's (sequence_extrinsic.hpp),
//     started from the time synchronisation's mean (eq:mean) and offset (without
//     synchronisation: the graph's C and time_offset_s); with that step disabled, its start.
//     statistics keep the graph's and the synchronisation's answers. covariance_6x6 ([rho; phi],
//     left, base frame; m, rad) = the whole-sequence step's jackknife covariance of C
//     (sequence_extrinsic.hpp) plus delta delta^T, delta = log(C_start C^-1) the step's move from
//     the graph's or the synchronisation's C: two models of the same data, whose disagreement is
//     a sample of an error every frame shares (refine_steps.hpp, sequence_step; not when the
//     step adopted a new clock offset, which the graph's C did not have). When refine's
//     own start lies beyond that covariance's 3-sigma ellipsoid, the step runs again from it and
//     the two answers' difference is added the same way (rerun_from_start). With that step disabled
//     or singular: the spread of the per-pair extrinsics, or without synchronisation the graph's
//     marginal covariance of C.
//   - refined poses are returned in the input map frames (b's through T_mapa_mapb).
//   - a's preparation (PreparedLidar: its deskewed, thinned frames, sweeps, hierarchy, bridges and
//     the hierarchy's poses) depends only on a's frames, poses and the options. It can be handed
//     from one call to the next (prepared_a), and is used when it was built from the same poses
//     bit for bit: a rig's targets on the base's own odometry share it (pipeline/rig.hpp).
//   - With time synchronisation on, the whole-sequence step checks that the drive pins the
//     clock offset down (sequence_offset.hpp, check_time_offset); when it does not, the
//     status is time_offset_untrusted and reason says why: the extrinsic absorbs v * (the
//     offset's error), so the result cannot be trusted. A caller who knows the offset turns
//     the synchronisation off and passes it as time_offset_s.
//   - The extrinsic must be confirmed by the LiDARs' own views: the cross links register b's
//     submaps to a's from the prediction of the starting extrinsic, and a kept link agrees
//     with it when the registration moved less than 1 deg and 1 m from that start
//     (cross_links.hpp). When fewer than max(min_cross_links, min_cross_link_ratio *
//     attempted) links agree, the status is extrinsic_unconfirmed, decided right after the
//     links, before the pose graph (the result's extrinsic and poses are then the inputs). The
//     graph cannot repair such a start: its ties hold C where it began and a planar drive leaves
//     the two trajectories' consistency degenerate. Measured (bench_trust and the seven-LiDAR rig,
//     docs/experiments/cross_link_agreement.md): wrong extrinsics JEEP accepted
//     had 0-1 agreeing links of 90 (64-tele, horizon-tele) and 0 of 538 (the rig's Tele, whose 27
//     kept links all moved 1.6-14.8 deg); right ones on the Tele pairs at least 8 of 90 and 35 of
//     538, except where no link is kept at all (64-tele seed 2's right extrinsic: every link's
//     inlier ratio under the 0.3 needed), which the reason names apart: the views overlap too
//     little to judge (docs/experiments/tele_cross_links.md). The weaker registrations are
//     counted then (weak links: converged, inlier ratio at least 0.1) and their agreement
//     reported, not used: from the truth 87-100 % of them agree on the Tele pairs, from starts
//     2 m, 3 deg or 2 deg off 0-44 %, but HOTS confirmed by them (64-tele seed 2) has no kept
//     link to tie the two LiDARs in its graph, and its whole-sequence step left the translation
//     2.3 m off and free along two directions. When fewer links were kept than must agree, the
//     rule looks again with each link's inlier ratio over b's points within a's reach
//     (refine_steps.hpp, second_look_within_reach): those links, kept and agreeing, confirm the
//     extrinsic and go into the graph (64-tele seed 2: 26 of 90, all agreeing from the truth;
//     docs/experiments/cross_links_within_reach.md).
//   - Nothing here throws (a throwing progress hook passes through) or prints; results are the
//     same for any number of threads.
#pragma once

#include <memory>
#include <utility>

#include "hots/refine_statistics.hpp"
#include "hots/refine_steps.hpp"
#include "ulc/core/batched_for.hpp"
#include "ulc/core/lidar_sequence.hpp"

namespace hots {

/// The share of refine done after each of its phases, for a progress bar: the phases' shares of
/// HOTS's time on the 60 s 64-32 drive (docs/experiments/long_drives.md: prepare 6 %, hierarchy
/// 35 %, cross links 27 %, graph and synchronisation 1 %, whole-sequence step 31 %).
using RefineProgress = ulc::StepProgress;

/// See the header comment. a and b are LidarSequences with their odometry poses; S is the
/// scalar of the prepared point clouds (float is plenty). progress (optional) is called on the
/// calling thread after each phase and within them: every few windows of the hierarchies and
/// registrations of the cross links (ulc/core/batched_for.hpp), after each sub-step of the
/// whole-sequence step; it may throw to stop refine there.
/// prepared_a (optional): a preparation of a (PreparedLidar) from an earlier call with the same
/// frames of a and options; it is used when it was built from a.poses bit for bit, else a is
/// prepared afresh. On return it holds the preparation used (once a was prepared), for the next
/// call: a base LiDAR's part of refine is then done once for several targets.
template <typename S = float, class SeqA, class SeqB>
RefineResult refine(const SeqA& a, const SeqB& b, const Isometry3d& extrinsic,
                    const RefineOptions& options = {}, const RefineProgress& progress = {},
                    std::shared_ptr<PreparedLidar<S>>* prepared_a = nullptr) {
  namespace d = hots_detail;
  RefineResult result;
  result.extrinsic = extrinsic;
  result.poses_a = a.poses;
  result.poses_b = b.poses;
  result.time_offset_s = options.time_offset_s;
  auto fail = [&](RefineStatus status, const char* why) {
    result.status = status;
    result.reason = why;
    return result;
  };
  if (const char* why = d::input_problem(a, b, extrinsic, options))
    return fail(RefineStatus::invalid_input, why);
  RefineStatistics& st = result.statistics;
  const bool reusable = prepared_a && *prepared_a && built_from(**prepared_a, a.poses);
  d::RefineState<S> s(a, b, reusable ? *prepared_a : nullptr);
  st.prepared_a_reused = reusable;
  s.start = extrinsic;
  s.mapa_mapb = d::map_b_in_map_a(s.a, s.b, extrinsic, options.time_offset_s);
  auto done = [&progress](double share) {
    if (progress) progress(share);
  };
  auto within = [&progress](double from, double to) {
    return ulc::progress_within(progress, from, to);
  };
  d::prepare_lidars(a, b, s, options, st, within(0.0, 0.06));
  done(0.06);
  d::build_hierarchies(s, options, st, within(0.06, 0.41));
  if (prepared_a) *prepared_a = s.a.prepared;
  done(0.41);
  const bool linked = d::link_lidars(s, options.time_offset_s, options, st, within(0.41, 0.68));
  done(0.68);
  if (!linked)
    return fail(RefineStatus::extrinsic_unconfirmed, d::unconfirmed_reason(st.link_verdict));
  d::build_graph(s, extrinsic, options, st);
  if (const RefineStatus status = d::solve_passes(s, options, result); status != RefineStatus::ok)
    return fail(status, result.reason);
  done(0.69);
  if (options.sequence.enabled && !d::sequence_step(s, options, result, within(0.69, 1.0)))
    return fail(RefineStatus::sequence_failed, result.reason);
  d::output_poses(s, result);
  if (!st.sequence.time_offset_trusted)
    return fail(RefineStatus::time_offset_untrusted, st.sequence.time_offset_doubt);
  return result;
}

}  // namespace hots
