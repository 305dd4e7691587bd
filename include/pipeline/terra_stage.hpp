// The pipeline's TERRA stage: the search on single frames or on local maps, as
// StageTuning::terra_source says, and the hypotheses the later stages start from.
//
//   - frames: frame i of each LiDAR (the same index, so clock offsets do not matter).
//   - maps: each LiDAR's local map over a window from frame i on (map_terra.hpp).
//   - automatic: the frame search first; the map search runs only when each LiDAR has at least
//     maps_min_frames frames in the window AND the frame search failed or overlaps in fewer
//     than maps_below_mask cells; the maps win when they succeed with a larger mask. The report
//     says which search was kept ("source") and why.
//   - The motion frame (motion_frame.hpp; not in the paper): whenever the local maps are built
//     (source maps, or automatic with enough frames in the window: built even when the frames
//     overlap well, to check them), the maps give a rotation of their own: the ground vote's
//     when it is confident (terra/ground_vote.hpp), else the ground and travel's, else the
//     unsure pooled vote's best guess (MotionFrameOptions::unsure_vote).
//     A kept answer within MotionFrameOptions::agree_for(method) of it stands (the paper's search
//     where it works); a farther one, or a failed search, is overruled: the motion frame's
//     rotation becomes the stage's answer and the first hypothesis. In automatic, frames that
//     overlap well but disagree with the motion frame also bring the map search in.
//   - Hypotheses (terra_hypotheses.hpp): the motion frame's rotation when it overruled, then the
//     kept search's distinct optima, best first, then the fallback's (its remaining optima,
//     then the other search's).
//   - Progress: "terra" from 0 to 1; the frame search gets a fifth of the bar when maps may
//     follow, the maps' building the next 60 %.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/map_terra.hpp"
#include "pipeline/motion_frame.hpp"
#include "pipeline/options.hpp"
#include "pipeline/pair_calibration.hpp"
#include "pipeline/terra_hypotheses.hpp"
#include "terra/search.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/pose_error.hpp"

namespace ulc {
namespace calibrate_detail {

/// What the TERRA stage reads, and the decisions made before any search.
template <class FramesA, class FramesB>
struct TerraInputs {
  const FramesA& frames_a;
  const std::vector<double>& times_a;
  const FramesB& frames_b;
  const std::vector<double>& times_b;
  const CalibrateOptions& options;
  terra::Lattice lattice;
  std::size_t window = 0;      ///< frames per LiDAR in the map window (the smaller)
  bool maps_possible = false;  ///< the map search may run
  double frame_share = 1.0;    ///< of the progress bar

  TerraInputs(const FramesA& fa, const std::vector<double>& ta, const FramesB& fb,
              const std::vector<double>& tb, const CalibrateOptions& o)
      : frames_a(fa),
        times_a(ta),
        frames_b(fb),
        times_b(tb),
        options(o),
        lattice(o.tuning.terra.lattice_size >= 2 ? o.tuning.terra.lattice_size : 0) {
    const TerraSourceOptions& src = o.tuning.terra_source;
    window = std::min(map_terra_detail::window_frames(ta, o.frame_index, src.maps),
                      map_terra_detail::window_frames(tb, o.frame_index, src.maps));
    maps_possible = src.source == TerraSource::maps ||
                    (src.source == TerraSource::automatic && window >= src.maps_min_frames);
    frame_share = maps_possible ? 0.2 : 1.0;
  }
};

/// The kept search, the one not kept when both ran (for the fallback hypotheses), and the
/// motion frame when the maps were built.
struct TerraSearches {
  terra::SearchResult kept;
  terra::SearchResult other;
  std::optional<MotionReport> motion;
  bool motion_used() const { return motion && motion->used; }
  bool ok() const { return kept.ok() || motion_used(); }
};

template <class FA, class FB>
terra::SearchResult search_frames(const TerraInputs<FA, FB>& in) {
  const std::size_t i = in.options.frame_index;
  terra::SearchParams p = in.options.tuning.terra;
  if (in.options.progress)
    p.progress = [&in](double f) { in.options.progress("terra", in.frame_share * f); };
  return p.lattice_size < 2
             ? terra::estimate_rotation(in.frames_a[i], in.frames_b[i], p)
             : terra::estimate_rotation(in.lattice, in.frames_a[i], in.frames_b[i], p);
}

/// Both LiDARs' local maps and their motion frame, on the bar after the frame search's share.
template <class FA, class FB>
auto build_maps(const TerraInputs<FA, FB>& in) {
  const CalibrateOptions& o = in.options;
  const double from = o.tuning.terra_source.source != TerraSource::maps ? in.frame_share : 0.0;
  std::function<void(double)> progress;
  if (o.progress)
    progress = [&o, from](double f) { o.progress("terra", from + 0.75 * (1.0 - from) * f); };
  return build_local_maps(in.frames_a, in.times_a, in.frames_b, in.times_b, o.frame_index,
                          o.tuning.terra_source.maps, progress);
}

template <class FA, class FB, class Maps>
MapTerraResult search_maps(const TerraInputs<FA, FB>& in, const Maps& maps) {
  const terra::SearchParams& params = in.options.tuning.terra;
  const MapTerraOptions& options = in.options.tuning.terra_source.maps;
  // in.lattice is empty when lattice_size < 2: the search then says so (invalid_input).
  return search_local_maps(in.lattice, maps, params, options);
}

/// Statistics of a TERRA search, in the report's form.
inline TerraReport terra_report(const terra::SearchResult& s, std::size_t frame_index,
                                std::size_t base_points, std::size_t target_points,
                                std::size_t lattice_size) {
  TerraReport t;
  t.status = s.status;
  t.reason = s.reason;
  t.rotation = s.rotation;
  t.distance = s.distance;
  t.mask_count = s.mask_count;
  t.frame_index = frame_index;
  t.base_points = base_points;
  t.target_points = target_points;
  t.lattice_size = lattice_size;
  t.stats = s.stats;
  return t;
}

template <class FA, class FB>
TerraReport frames_report(const TerraInputs<FA, FB>& in, const terra::SearchResult& s,
                          std::string why) {
  const std::size_t i = in.options.frame_index;
  TerraReport t = terra_report(s, i, traits::size(in.frames_a[i]), traits::size(in.frames_b[i]),
                               in.options.tuning.terra.lattice_size);
  t.source = TerraSource::frames;
  t.source_reason = std::move(why);
  t.frames_mask_count = s.mask_count;
  t.frames_status = s.status;
  return t;
}

template <class FA, class FB>
TerraReport maps_report(const TerraInputs<FA, FB>& in, const MapTerraResult& m, std::string why) {
  TerraReport t = terra_report(m.search, in.options.frame_index, m.base.points, m.target.points,
                               in.options.tuning.terra.lattice_size);
  t.source = TerraSource::maps;
  t.source_reason = std::move(why);
  t.base_map = m.base;
  t.target_map = m.target;
  return t;
}

/// automatic, once the frame search `f` overlapped too little (or disagreed with the motion
/// frame): the map search, kept when it succeeds with a larger mask.
template <class FA, class FB, class Maps>
TerraSearches frames_or_maps(const TerraInputs<FA, FB>& in, const terra::SearchResult& f,
                             const Maps& maps, const std::string& frames_said,
                             TerraReport& report) {
  const MapTerraResult m = search_maps(in, maps);
  if (m.ok() && (!f.ok() || m.search.mask_count > f.mask_count)) {
    report = maps_report(
        in, m,
        "automatic: " + frames_said + "; the maps in " + std::to_string(m.search.mask_count));
    report.frames_mask_count = f.mask_count;
    report.frames_status = f.status;
    return {m.search, f, m.motion};
  }
  report = frames_report(
      in, f,
      "automatic: " + frames_said + ", but the map search " +
          (m.ok() ? "overlaps less (" + std::to_string(m.search.mask_count) + " cells)"
                  : std::string("failed: ") + m.search.reason));
  report.base_map = m.base;
  report.target_map = m.target;
  return {f, m.search, m.motion};
}

/// How far (deg) a search's answer lies from the motion frame's rotation (180 when it failed).
inline double off_motion_deg(const terra::SearchResult& s, const MotionReport& m) {
  return s.ok() ? rotation_error_rad(m.rotation, s.rotation) / kRadPerDeg : 180.0;
}

/// The motion frame's vote on the kept answer (see the conventions above), into the report.
inline void motion_vote(TerraSearches& searches, const MotionFrameOptions& o, TerraReport& report) {
  if (!searches.motion) return;
  MotionReport& m = *searches.motion;
  if (m.ok) {
    m.search_off_deg = off_motion_deg(searches.kept, m);
    m.used = m.search_off_deg > o.agree_for(m.method);
  }
  if (m.used) {
    if (!searches.kept.ok())
      report.reason = "the search failed (" + report.reason + "); the motion frame stands in";
    report.rotation = m.rotation;
    report.status = terra::SearchStatus::ok;
  }
  report.motion = m;
}

/// automatic with the maps built: the frames kept when they overlap well and the motion frame
/// does not contradict them, else the map search as well.
template <class FA, class FB>
TerraSearches automatic_with_maps(const TerraInputs<FA, FB>& in, const terra::SearchResult& f,
                                  TerraReport& report) {
  const TerraSourceOptions& src = in.options.tuning.terra_source;
  const auto maps = build_maps(in);
  const bool overlap = f.ok() && f.mask_count >= src.maps_below_mask;
  const bool contradicted = maps.motion.ok && off_motion_deg(f, maps.motion) >
                                                  src.maps.motion.agree_for(maps.motion.method);
  if (overlap && !contradicted) {
    report = frames_report(in, f,
                           "automatic: the frames overlap in " + std::to_string(f.mask_count) +
                               " cells (maps are tried below " +
                               std::to_string(src.maps_below_mask) + ")");
    report.base_map = maps.a.stats;
    report.target_map = maps.b.stats;
    return {f, {}, maps.motion};
  }
  const std::string frames_said =
      overlap ? "the frames overlap in " + std::to_string(f.mask_count) +
                    " cells but disagree with the motion frame"
      : f.ok() ? "the frames overlap in only " + std::to_string(f.mask_count) + " cells"
               : std::string("the frame search failed (") + terra::to_string(f.status) + ")";
  return frames_or_maps(in, f, maps, frames_said, report);
}

/// The searches StageTuning::terra_source asks for, before the motion frame's vote.
template <class FA, class FB>
TerraSearches run_searches(const TerraInputs<FA, FB>& in, TerraReport& report) {
  const TerraSourceOptions& src = in.options.tuning.terra_source;
  if (src.source == TerraSource::maps) {
    const MapTerraResult m = search_maps(in, build_maps(in));
    report = maps_report(in, m, "terra_source = maps");
    return {m.search, {}, m.motion};
  }
  const terra::SearchResult f = search_frames(in);
  if (src.source == TerraSource::frames) {
    report = frames_report(in, f, "terra_source = frames");
    return {f, {}, std::nullopt};
  }
  if (!in.maps_possible) {
    report = frames_report(in, f,
                           "automatic: " + std::to_string(in.window) +
                               " frame(s) per LiDAR in the map window (maps need " +
                               std::to_string(src.maps_min_frames) + ")");
    return {f, {}, std::nullopt};
  }
  return automatic_with_maps(in, f, report);
}

/// The search StageTuning::terra_source asks for and the motion frame's vote; fills `report`
/// (all but seconds).
template <class FA, class FB>
TerraSearches run_terra_search(const TerraInputs<FA, FB>& in, TerraReport& report) {
  TerraSearches searches = run_searches(in, report);
  motion_vote(searches, in.options.tuning.terra_source.maps.motion, report);
  return searches;
}

/// The rotations the later stages start from, best first; `first_fallback` is the index of the
/// first of the fallback's.
struct StartRotations {
  std::vector<terra::RotationCandidate> candidates;
  std::vector<TerraSource> sources;  ///< the search each candidate is an optimum of
  std::size_t first_fallback = 0;
  bool motion_first = false;  ///< candidates[0] is the motion frame's rotation
  /// The ground vote's extrinsic, when it answered (window_vote.hpp): its lever arm along the
  /// ground and its height difference. A candidate within vote_agree_deg of its rotation starts
  /// from this translation instead of the origin (a Tele-15 2.3 m from a VLP-16 lies beyond
  /// JEEP's start search, which shifts its guess by 2 m: bench_rig, 16-tele).
  std::optional<Isometry3d> vote;
  double vote_agree_deg = 0.0;

  /// Where the later stages start from for candidate k.
  Isometry3d start(std::size_t k) const {
    Isometry3d t = Isometry3d::Identity();
    t.linear() = candidates[k].rotation;
    if (vote && rotation_error_rad(vote->linear(), t.linear()) <= vote_agree_deg * kRadPerDeg)
      t.translation() = vote->translation();
    return t;
  }
};

/// The ground vote's extrinsic when it was the maps' confident answer.
inline std::optional<Isometry3d> vote_extrinsic(const std::optional<MotionReport>& m) {
  if (!m || !m->ok || m->method != "ground vote") return std::nullopt;
  Isometry3d t = Isometry3d::Identity();
  t.linear() = m->vote.rotation;
  t.translation() = m->vote.translation;
  return t;
}

inline StartRotations start_rotations(const TerraSearches& searches, TerraSource kept_source,
                                      const HypothesisOptions& o,
                                      const MotionFrameOptions& motion = {}) {
  const double separation = o.separation_deg * kRadPerDeg;
  const std::size_t count = std::max<std::size_t>(1, o.count);
  StartRotations out;
  out.vote = vote_extrinsic(searches.motion);
  out.vote_agree_deg = motion.vote_agree_deg;
  if (searches.motion_used()) {
    terra::RotationCandidate c;
    c.rotation = searches.motion->rotation;
    c.distance = 0.0;  // not a search optimum: no eq:feature_dis
    out.candidates.push_back(c);
    out.sources.push_back(TerraSource::maps);
    out.motion_first = true;
    for (const auto& k : fallback_hypotheses(searches.kept, out.candidates, count - 1, separation))
      out.candidates.push_back(k);
  } else {
    out.candidates = terra_hypotheses(searches.kept, count, separation);
  }
  out.first_fallback = out.candidates.size();
  out.sources.resize(out.candidates.size(), kept_source);
  const TerraSource other_source =
      kept_source == TerraSource::maps ? TerraSource::frames : TerraSource::maps;
  for (const terra::SearchResult* search : {&searches.kept, &searches.other}) {
    const std::size_t left = o.fallback - (out.candidates.size() - out.first_fallback);
    for (const auto& c : fallback_hypotheses(*search, out.candidates, left, separation)) {
      out.candidates.push_back(c);
      out.sources.push_back(search == &searches.kept ? kept_source : other_source);
    }
  }
  return out;
}

}  // namespace calibrate_detail
}  // namespace ulc
