// A PairCalibration as the result file's entry (docs/design.md, "Result file"; io/result_file.hpp).
//
// Conventions this header owns:
//   - time_offset_s is the caller's known offset or HOTS's when it succeeded, otherwise 0
//     (clocks assumed synchronised); covariance_6x6 is the last stage's (HOTS's or JEEP's).
//   - "stages" holds one object per stage that ran ("terra", "jeep", "hots"); "timing_s" always
//     holds every stage key of docs/design.md ("terra", "jeep", "odometry", "hots", "total"), 0
//     for a stage that did not run.
//   - Angles in the stage objects are degrees, distances metres, times seconds.
// An I/O-side header of component ulc::results (it builds ulc::Json, nlohmann::ordered_json):
// the pipeline's headers hold no JSON, and unlike pipeline/calibrate.hpp this is not part of the
// -fno-exceptions promise.
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/pair_calibration.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/io/json_file.hpp"
#include "ulc/io/result_file.hpp"

namespace ulc::io {

namespace result_detail {

inline Json stage_stats(const terra::StageStats& s) {
  Json j = Json::object();
  j["rotations"] = s.rotations;
  j["seconds"] = s.seconds;
  return j;
}

inline Json local_map_stats(const LocalMapStats& m) {
  Json j = Json::object();
  j["frames"] = m.frames;
  j["stacked_points"] = m.stacked_points;
  j["points"] = m.points;
  j["voxel_m"] = m.voxel_used;
  j["odometry_status"] = odometry::to_string(m.odometry_status);
  j["odometry_reason"] = m.odometry_reason;
  j["odometry_failed_steps"] = m.odometry_failed_steps;
  j["seconds"] = m.seconds;
  return j;
}

inline Json ground_vote_report(const terra::GroundVoteResult& v) {
  Json j = Json::object();
  j["ok"] = v.ok;
  j["reason"] = v.reason;
  j["rpy_deg"] = vector_to_json(rpy_from_rotation(v.rotation) * kDegPerRad);
  j["translation_m"] = vector_to_json(v.translation);
  j["score"] = v.score;
  // Infinite when no rival peak: JSON has no infinity.
  j["margin"] = std::isfinite(v.margin) ? Json(v.margin) : Json();
  j["points"] = v.points;
  j["target_plane"] = v.target_plane;
  j["base_ring_gap_deg"] = v.base_ring_gap_deg;
  return j;
}

inline Json motion_report(const MotionReport& m) {
  Json j = Json::object();
  j["ok"] = m.ok;
  j["reason"] = m.reason;
  if (m.ok) j["rpy_deg"] = vector_to_json(rpy_from_rotation(m.rotation) * kDegPerRad);
  j["travel_base_m"] = m.travel_base_m;
  j["travel_target_m"] = m.travel_target_m;
  j["planes_base"] = m.planes_base;
  j["planes_target"] = m.planes_target;
  j["planes_matched"] = m.planes_matched;
  if (m.ok) j["search_off_deg"] = m.search_off_deg;
  j["used"] = m.used;
  j["method"] = m.method;
  if (m.vote_ran) {
    Json vote = ground_vote_report(m.vote);
    vote["window_frame"] = m.vote_frame;
    vote["frames_voted"] = m.votes;
    vote["frames_confident"] = m.votes_confident;
    vote["frames_agreeing"] = m.votes_agreeing;
    vote["pooled"] = m.vote_pooled;
    j["ground_vote"] = std::move(vote);
  }
  return j;
}

}  // namespace result_detail

/// stages.terra: the search's outcome and the statistics a profiler needs; "source" says
/// whether it compared frames or local maps ("base_map" / "target_map" hold the maps'
/// statistics when the maps were built, "frames_mask_count" the frame search's overlap,
/// "motion" the motion frame's rotation and whether it overruled the search).
inline Json terra_to_json(const TerraReport& t) {
  using result_detail::stage_stats;
  Json j = Json::object();
  j["status"] = terra::to_string(t.status);
  j["reason"] = t.reason;
  j["frame_index"] = t.frame_index;
  j["rpy_deg"] = vector_to_json(rpy_from_rotation(t.rotation) * kDegPerRad);
  j["distance"] = t.distance;
  j["mask_count"] = t.mask_count;
  j["base_points"] = t.base_points;
  j["target_points"] = t.target_points;
  j["lattice_size"] = t.lattice_size;
  j["d1_used_m"] = t.stats.d1_used;
  j["d1_adapted"] = t.stats.d1_adapted;
  j["base_cells_beyond_d1"] = t.stats.base_beyond_d1;
  j["target_cells_beyond_d1"] = t.stats.target_beyond_d1;
  Json stages = Json::object();
  stages["overlap"] = stage_stats(t.stats.overlap);
  stages["coarse"] = stage_stats(t.stats.coarse);
  stages["fine"] = stage_stats(t.stats.fine);
  j["search_stages"] = std::move(stages);
  j["rotations_evaluated"] = t.stats.rotations();
  j["descriptor_seconds"] = t.stats.descriptor_seconds;
  j["seconds"] = t.seconds;
  j["source"] = to_string(t.source);
  j["source_reason"] = t.source_reason;
  if (t.frames_mask_count) {
    j["frames_mask_count"] = *t.frames_mask_count;
    j["frames_status"] = terra::to_string(t.frames_status);
  }
  if (t.base_map) j["base_map"] = result_detail::local_map_stats(*t.base_map);
  if (t.target_map) j["target_map"] = result_detail::local_map_stats(*t.target_map);
  if (t.motion) j["motion"] = result_detail::motion_report(*t.motion);
  Json hypotheses = Json::array();
  for (const TerraHypothesis& h : t.hypotheses) {
    Json e = Json::object();
    e["source"] = h.motion ? std::string("motion") : std::string(to_string(h.source));
    e["rpy_deg"] = vector_to_json(rpy_from_rotation(h.rotation) * kDegPerRad);
    e["distance"] = h.distance;
    e["mask_count"] = h.mask_count;
    e["outcome"] = h.status == CalibrateStatus::ok
                       ? std::string("ok")
                       : std::string(to_string(h.status)) + ": " + h.reason;
    e["seconds"] = h.seconds;
    if (h.off_ground_overlap) e["off_ground_overlap"] = *h.off_ground_overlap;
    hypotheses.push_back(std::move(e));
  }
  j["hypotheses"] = std::move(hypotheses);
  j["hypothesis_used"] = t.hypothesis_used;
  return j;
}

/// stages.jeep: rounds, status and the last calibration phase's cost and inliers.
inline Json jeep_to_json(const JeepReport& r) {
  Json j = Json::object();
  j["status"] = jeep::to_string(r.status);
  j["reason"] = r.reason;
  j["rounds"] = r.rounds;
  j["frame_pairs"] = r.frame_pairs;
  j["stacked_frames_base"] = r.stacked_frames_base;
  j["stacked_frames_target"] = r.stacked_frames_target;
  j["stack_covariance_scale"] = r.stack_covariance_scale;
  j["initial_T_base_target"] = matrix_to_json(r.initial.matrix());
  j["calibration_status"] = to_string(r.calibration_status);
  j["final_cost"] = r.final_cost;
  j["final_inliers"] = r.final_inliers;
  j["final_rmse_m"] = r.final_rmse;
  j["accepted"] = r.accepted;
  j["overlap"] = r.overlap;
  j["directional_overlap"] = r.directional_overlap;
  j["off_ground_overlap"] = r.off_ground_overlap;
  j["two_way"] = r.two_way;
  j["two_way_gap_m"] = r.two_way_gap_translation;
  j["two_way_gap_deg"] = r.two_way_gap_rotation * kDegPerRad;
  j["start_basins"] = r.start_basins;
  j["start_chosen"] = r.start_chosen;
  j["judged_by_hots"] = r.judged_by_hots;
  // The final registration's weakest direction (ulc/core/observability.hpp), null when its
  // maps disagree.
  j["weakest_share"] = r.observability ? Json(r.observability->weakest_share) : Json();
  j["shares"] = r.observability ? vector_to_json(r.observability->shares) : Json();
  j["seconds"] = r.seconds;
  j["target_speed_mps"] = r.target_speed_mps;
  // A static snapshot's free-space check (pipeline/free_space.hpp), null when it did not run.
  Json free_space;
  if (r.free_space) {
    free_space["judged"] = r.free_space->judged;
    free_space["contradicting"] = r.free_space->contradicting;
    free_space["share"] = r.free_space->share();
    free_space["rays_judged"] = r.free_space->rays_judged;
    free_space["rays_through"] = r.free_space->rays_through;
    free_space["through_share"] = r.free_space->through_share();
  }
  j["free_space"] = std::move(free_space);
  return j;
}

/// stages.hots.status: hots::refine's status, or "skipped" / "not_run" when it did not run.
inline std::string hots_status_text(const HotsReport& h) {
  switch (h.run) {
    case HotsRun::skipped:
      return "skipped";
    case HotsRun::odometry_failed:
      return "not_run";
    case HotsRun::odometry_degenerate:
      return "odometry_degenerate";
    default:
      return hots::to_string(h.status);
  }
}

/// Each cross-link registration HOTS tried, one row each under named columns (a result file
/// holds tens to a few hundred).
inline Json cross_link_records_to_json(const std::vector<hots::CrossLinkRecord>& records) {
  Json rows = Json::array();
  for (const auto& r : records)
    rows.push_back(Json::array({r.layer, r.converged ? 1 : 0, r.inlier_ratio,
                                r.moved_rad * kDegPerRad, r.moved_m, r.inlier_ratio_in_reach}));
  Json j = Json::object();
  j["columns"] = Json::array(
      {"layer", "converged", "inlier_ratio", "moved_deg", "moved_m", "inlier_ratio_in_reach"});
  j["rows"] = std::move(rows);
  return j;
}

/// stages.hots.stillness: whether the rig stood still (pipeline/stillness.hpp).
inline Json stillness_to_json(const StillnessReport& s) {
  Json j = Json::object();
  j["still"] = s.still;
  j["decided"] = s.decided;
  j["frames_compared"] = s.frames_compared;
  j["span_s"] = s.span_s;
  j["max_travel_m"] = s.max_travel_m;
  j["max_turn_deg"] = s.max_turn_deg;
  j["min_condition"] = s.min_condition;
  j["min_inlier_ratio"] = s.min_inlier_ratio;
  j["reason"] = s.reason;
  return j;
}

/// stages.hots: the odometry that fed it, the graph's and the time synchronisation's statistics
/// and the spread-against-offset curve.
inline Json hots_to_json(const HotsReport& h) {
  const hots::RefineStatistics& s = h.statistics;
  Json j = Json::object();
  j["status"] = hots_status_text(h);
  j["reason"] = h.reason;
  // Skipped for want of frames: no odometry ran either.
  j["odometry_status"] = h.run == HotsRun::skipped ? "" : odometry::to_string(h.odometry_status);
  j["odometry_reason"] = h.odometry_reason;
  j["odometry_failed_steps"] = h.odometry_failed_steps;
  j["odometry_condition"] = h.odometry_condition;
  j["frames_base"] = h.frames_base;
  j["frames_target"] = h.frames_target;
  j["initial_T_base_target"] = matrix_to_json(h.initial.matrix());
  j["graph_T_base_target"] = matrix_to_json(s.graph_extrinsic.matrix());
  // The whole-sequence step rerun from HOTS's start when the start lay beyond its answer's
  // 3-sigma ellipsoid (hots/refine_steps.hpp, rerun_from_start); null when it did not run.
  j["rerun_T_base_target"] =
      s.sequence_rerun.ok() ? matrix_to_json(s.sequence_rerun.extrinsic.matrix()) : Json();
  j["windows"] = s.windows;
  j["failed_windows"] = s.failed_windows;
  j["planes"] = s.planes;
  j["ba_factors"] = s.ba_factors;
  j["cross_links"] = s.cross_links;
  j["cross_links_attempted"] = s.cross_links_attempted;
  j["cross_links_agreeing"] = s.cross_links_agreeing;
  j["cross_links_converged"] = s.cross_links_converged;
  j["cross_links_weak"] = s.cross_links_weak;
  j["cross_links_weak_agreeing"] = s.cross_links_weak_agreeing;
  j["link_verdict"] = hots::to_string(s.link_verdict);
  j["links_judged_within_reach"] = s.links_judged_within_reach;
  j["cross_link_inlier_ratio_median"] = s.cross_link_inlier_ratio_median;
  j["cross_link_registrations"] = cross_link_records_to_json(s.cross_link_records);
  j["extrinsic_ties"] = s.extrinsic_ties;
  j["boundary_factors"] = s.boundary_factors;
  j["boundary_links"] = s.boundary_links;
  j["boundary_bridges"] = s.boundary_bridges;
  j["graph_iterations"] = s.graph_iterations;
  j["graph_initial_cost"] = s.graph_initial_cost;
  j["graph_cost"] = s.graph_cost;
  j["time_offset_s"] = h.time_offset_s;
  j["time_sync_spread"] = s.time_sync_spread;
  j["time_sync_pairs"] = s.time_sync_pairs;
  j["sync_time_offset_s"] = s.sync_time_offset_s;
  j["sync_significant"] = s.sync_significant;
  // The whole-sequence step's offset and its trust check (sequence_extrinsic.hpp).
  j["joint_time_offset_s"] = s.sequence.joint_time_offset_s;
  j["time_offset_refined"] = s.sequence.time_offset_refined;
  j["time_offset_checked"] = s.sequence.time_offset_checked;
  j["time_offset_trusted"] = s.sequence.time_offset_trusted;
  Json halves = Json::array();
  for (const double half : s.sequence.half_time_offset_s) halves.push_back(half);
  j["half_time_offsets_s"] = std::move(halves);
  j["time_observability"] = s.sequence.time_observability;
  // The whole-sequence step's weakest direction (ulc/core/observability.hpp), null when the
  // step did not run.
  j["weakest_share"] = h.observability ? Json(h.observability->weakest_share) : Json();
  j["shares"] = h.observability ? vector_to_json(h.observability->shares) : Json();
  Json curve = Json::array();
  for (const auto& [offset, spread] : h.spread_curve) {
    Json point = Json::array();
    point.push_back(offset);
    point.push_back(spread);
    curve.push_back(std::move(point));
  }
  j["spread_curve"] = std::move(curve);  // [[offset_s, spread], ...]
  Json phases = Json::object();
  phases["prepare"] = s.prepare_seconds;
  phases["hierarchy"] = s.hierarchy_seconds;
  phases["cross_links"] = s.links_seconds;
  phases["graph"] = s.graph_seconds;
  phases["time_sync"] = s.sync_seconds;
  phases["sequence"] = s.sequence_seconds;
  j["phase_seconds"] = std::move(phases);
  j["odometry_seconds"] = h.odometry_seconds;
  j["odometry"] = to_string(h.odometry);  // "joint" or "base"
  j["odometry_choice"] = h.odometry_choice;
  j["odometry_reused"] = h.odometry_reused;
  j["base_prepared_reused"] = h.base_prepared_reused;
  j["seconds"] = h.seconds;
  // Null when the check did not run (too few frames, or off).
  j["stillness"] = h.stillness ? stillness_to_json(*h.stillness) : Json();
  return j;
}

/// "clock": where the offset came from and, when nobody estimated it, its effect and the lag
/// the motions show (pipeline/vouch.hpp).
inline Json clock_to_json(const ClockReport& c) {
  Json j = Json::object();
  j["source"] = to_string(c.source);
  j["note"] = c.note;
  if (c.source != ClockSource::not_estimated) return j;
  j["verdict"] = c.verdict;
  j["speed_mps"] = c.speed_mps;
  j["translation_per_ms_m"] = c.translation_per_ms_m;
  j["lag_checked"] = c.lag_checked;
  if (c.lag_checked) {
    j["lag_s"] = c.lag_s;
    j["lag_sigma_s"] = std::isfinite(c.lag_sigma_s) ? Json(c.lag_sigma_s) : Json();
    j["lag_samples"] = c.lag_samples;
    j["lag_window_s"] = c.lag_window_s;
  }
  return j;
}

/// "point_times": each LiDAR's source of per-point times and what was done without them.
inline Json point_times_to_json(const PointTimesReport& base, const PointTimesReport& target) {
  Json j = Json::object();
  for (const auto& [key, p] :
       {std::pair<const char*, const PointTimesReport*>{"base", &base}, {"target", &target}}) {
    Json e = Json::object();
    e["source"] = to_string(p->source);
    e["frames_without"] = p->frames_without;
    e["note"] = p->note;
    j[key] = std::move(e);
  }
  return j;
}

/// The result-file entry for target `target` against base `base`.
inline PairResult to_pair_result(const PairCalibration& c, const std::string& base,
                                 const std::string& target) {
  PairResult r;
  r.base = base;
  r.target = target;
  r.success = c.success;
  r.status = to_string(c.status);
  r.reason = c.reason;
  r.T_base_target = c.T_base_target;
  r.time_offset_s = c.time_offset_s;
  if (c.covariance_6x6) r.covariance_6x6 = *c.covariance_6x6;
  if (c.clock) r.clock = clock_to_json(*c.clock);
  r.point_times = point_times_to_json(c.point_times_base, c.point_times_target);
  r.observability_problem = c.observability_problem;
  if (!c.observability_problem.empty()) r.weakest_share = c.weakest_share;
  r.unobservable = c.unobservable;
  r.stages = Json::object();
  if (c.terra) r.stages["terra"] = terra_to_json(*c.terra);
  if (c.jeep) r.stages["jeep"] = jeep_to_json(*c.jeep);
  if (c.hots) r.stages["hots"] = hots_to_json(*c.hots);
  r.timing_s = Json::object();
  r.timing_s["terra"] = c.timing_s.terra;
  r.timing_s["jeep"] = c.timing_s.jeep;
  r.timing_s["odometry"] = c.timing_s.odometry;
  r.timing_s["hots"] = c.timing_s.hots;
  r.timing_s["total"] = c.timing_s.total;
  return r;
}

}  // namespace ulc::io
