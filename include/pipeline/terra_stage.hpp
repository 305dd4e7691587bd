// The pipeline's TERRA stage: the search on single frames or on local maps, as
// StageTuning::terra_source says, and the hypotheses the later stages start from.
//
//   - frames: frame i of each LiDAR (the same index, so clock offsets do not matter).
//   - maps: each LiDAR's local map over a window from frame i on (map_terra.hpp).
//   - automatic: the frame search first; the map search runs only when each LiDAR has at least
//     maps_min_frames frames in the window AND the frame search failed or overlaps in fewer
//     than maps_below_mask cells; the maps win when they succeed with a larger mask. The report
//     says which search was kept ("source") and why.
//   - Hypotheses (terra_hypotheses.hpp): the kept search's distinct optima, best first, then the
//     fallback's (its remaining optima, then the other search's).
//   - Progress: "terra" from 0 to 1; the frame search gets a fifth of the bar when maps may
//     follow.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/map_terra.hpp"
#include "pipeline/options.hpp"
#include "pipeline/pair_calibration.hpp"
#include "pipeline/terra_hypotheses.hpp"
#include "terra/search.hpp"
#include "ulc/core/point_traits.hpp"

namespace ulc {
namespace calibrate_detail {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

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

/// The kept search, and the one not kept when both ran (for the fallback hypotheses).
struct TerraSearches {
  terra::SearchResult kept;
  terra::SearchResult other;
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

template <class FA, class FB>
MapTerraResult search_maps(const TerraInputs<FA, FB>& in) {
  const CalibrateOptions& o = in.options;
  const double from = o.tuning.terra_source.source != TerraSource::maps ? in.frame_share : 0.0;
  std::function<void(double)> progress;
  if (o.progress) progress = [&o, from](double f) { o.progress("terra", from + (1.0 - from) * f); };
  const terra::SearchParams& params = o.tuning.terra;
  const MapTerraOptions& maps = o.tuning.terra_source.maps;
  return params.lattice_size < 2 ? map_terra(in.frames_a, in.times_a, in.frames_b, in.times_b,
                                             o.frame_index, params, maps, progress)
                                 : map_terra(in.lattice, in.frames_a, in.times_a, in.frames_b,
                                             in.times_b, o.frame_index, params, maps, progress);
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

/// automatic, once the frame search `f` overlapped too little: the map search, kept when it
/// succeeds with a larger mask.
template <class FA, class FB>
TerraSearches frames_or_maps(const TerraInputs<FA, FB>& in, const terra::SearchResult& f,
                             TerraReport& report) {
  const MapTerraResult m = search_maps(in);
  const std::string frames_said =
      f.ok() ? "the frames overlap in only " + std::to_string(f.mask_count) + " cells"
             : std::string("the frame search failed (") + terra::to_string(f.status) + ")";
  if (m.ok() && (!f.ok() || m.search.mask_count > f.mask_count)) {
    report = maps_report(
        in, m,
        "automatic: " + frames_said + "; the maps in " + std::to_string(m.search.mask_count));
    report.frames_mask_count = f.mask_count;
    report.frames_status = f.status;
    return {m.search, f};
  }
  report = frames_report(
      in, f,
      "automatic: " + frames_said + ", but the map search " +
          (m.ok() ? "overlaps less (" + std::to_string(m.search.mask_count) + " cells)"
                  : std::string("failed: ") + m.search.reason));
  report.base_map = m.base;
  report.target_map = m.target;
  return {f, m.search};
}

/// The search StageTuning::terra_source asks for; fills `report` (all but seconds).
template <class FA, class FB>
TerraSearches run_terra_search(const TerraInputs<FA, FB>& in, TerraReport& report) {
  const TerraSourceOptions& src = in.options.tuning.terra_source;
  if (src.source == TerraSource::maps) {
    const MapTerraResult m = search_maps(in);
    report = maps_report(in, m, "terra_source = maps");
    return {m.search, {}};
  }
  const terra::SearchResult f = search_frames(in);
  if (src.source == TerraSource::frames) {
    report = frames_report(in, f, "terra_source = frames");
    return {f, {}};
  }
  if (!in.maps_possible) {
    report = frames_report(in, f,
                           "automatic: " + std::to_string(in.window) +
                               " frame(s) per LiDAR in the map window (maps need " +
                               std::to_string(src.maps_min_frames) + ")");
    return {f, {}};
  }
  if (f.ok() && f.mask_count >= src.maps_below_mask) {
    report = frames_report(in, f,
                           "automatic: the frames overlap in " + std::to_string(f.mask_count) +
                               " cells (maps are tried below " +
                               std::to_string(src.maps_below_mask) + ")");
    return {f, {}};
  }
  return frames_or_maps(in, f, report);
}

/// The rotations the later stages start from, best first; `first_fallback` is the index of the
/// first of the fallback's.
struct StartRotations {
  std::vector<terra::RotationCandidate> candidates;
  std::vector<TerraSource> sources;  ///< the search each candidate is an optimum of
  std::size_t first_fallback = 0;
};

inline StartRotations start_rotations(const TerraSearches& searches, TerraSource kept_source,
                                      const HypothesisOptions& o) {
  const double separation = o.separation_deg * kRadPerDeg;
  StartRotations out;
  out.candidates = terra_hypotheses(searches.kept, std::max<std::size_t>(1, o.count), separation);
  out.first_fallback = out.candidates.size();
  out.sources.assign(out.candidates.size(), kept_source);
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
