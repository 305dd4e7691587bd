// The options of ulc::calibrate_pair (ulc/calibrate.hpp): what a caller decides and each
// stage's tuning, held by value. Light on purpose: it includes the stages' option headers only,
// never the algorithms, so that a file calling the pipeline compiles in seconds
// (docs/BENCHMARKS.md, "Compile time").
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hots/options.hpp"
#include "jeep/options.hpp"
#include "terra/search_params.hpp"
#include "ulc/calibrate/map_terra_options.hpp"
#include "ulc/calibrate/stages.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// Called with the running stage's name ("terra", "jeep", "odometry", "hots") and its fraction
/// done.
using CalibrateProgress = std::function<void(const std::string& stage, double fraction)>;

/// What TERRA compares: single frames (the paper's default) or each LiDAR's local map over a
/// short window (the paper's remedy for small overlap, map_terra.hpp).
enum class TerraSource {
  automatic,  ///< frames first; maps when the sequences allow and the frames overlap too little
  frames,     ///< frame frame_index of each LiDAR
  maps        ///< local maps from frame_index on (a single frame gives a one-frame map)
};

inline const char* to_string(TerraSource s) {
  switch (s) {
    case TerraSource::automatic:
      return "automatic";
    case TerraSource::frames:
      return "frames";
    default:
      return "maps";
  }
}

/// Everything calibrate_pair can be told; the defaults are the paper's.
struct CalibrateOptions {
  terra::SearchParams terra;  ///< N = 10000, d1 = 20 m, d2 = 5 m, alpha = 2, 10/1 deg strides
  TerraSource terra_source = TerraSource::automatic;
  MapTerraOptions terra_maps;  ///< window, thinning and odometry of the local maps
  /// automatic: the maps are tried only when each LiDAR has at least this many frames in the
  /// window from frame_index (a single frame, or a static snapshot, stays on frames) ...
  std::size_t terra_maps_min_frames = 5;
  /// ... and the frame search failed or its eq:mask count at its answer is below this many
  /// cells. The map result is then kept when it succeeded with a larger mask count.
  std::size_t terra_maps_below_mask = 100;
  /// TERRA's hypotheses (ulc/calibrate/terra_hypotheses.hpp): when HOTS runs on a moving rig
  /// and the stages after TERRA's best rotation fail in a way that points at the rotation
  /// (JEEP fails, or HOTS finds the LiDARs' views disagree with it: extrinsic_unconfirmed),
  /// the search's next distinct optima are tried in turn, up to this many in all; the first
  /// success wins. 1 = the paper's single answer. Not in the paper.
  std::size_t terra_hypotheses = 4;
  /// ... and when all of those fail, up to this many more (terra_hypotheses.hpp,
  /// fallback_hypotheses): the kept search's remaining optima, then the other search's when
  /// both ran. With jeep among the stages, each must pass JEEP's own acceptance before HOTS
  /// runs from it (no hand-over: lower-ranked optima get the stricter test, and a refused one
  /// costs JEEP alone, 1-4 s); HOTS's cross links judge every one.
  /// 0 = none. Not in the paper.
  std::size_t terra_fallback_hypotheses = 8;
  /// Optima closer than this to a better one are the same hypothesis (JEEP converges from a few
  /// degrees).
  double terra_hypothesis_separation_deg = 10.0;
  /// When HOTS runs on a moving rig, its cross links judge JEEP's extrinsic, not JEEP's own
  /// acceptance: a JEEP that settled but was rejected, or did not settle, hands its extrinsic
  /// to HOTS, and only HOTS's refusal (extrinsic_unconfirmed) ends the attempt. On narrow-FoV
  /// targets JEEP's acceptance refuses right extrinsics (the seven-LiDAR rig's Tele,
  /// docs/experiments/terra_hypotheses.md), while the cross links separate right from wrong.
  /// false: any JEEP failure ends the attempt. Not in the paper.
  bool hots_judges_jeep = true;
  jeep::JeepOptions jeep;          ///< K = 5 frame pairs, at most 10 rounds
  jeep::OdometryOptions odometry;  ///< the odometry over all frames that feeds HOTS
  hots::RefineOptions hots;        ///< windows of 5, 3 layers, time synchronisation on
  std::vector<Stage> stages{Stage::terra, Stage::jeep, Stage::hots};
  /// Single frames or a static rig (fewer frames than this per LiDAR from frame_index): HOTS
  /// has no motion to work with, so after TERRA or JEEP it is skipped (stages.hots says so) and
  /// their extrinsic is the answer; as the only stage it fails.
  std::size_t hots_min_frames = 10;
  std::size_t frame_index = 0;        ///< TERRA's frame, and the first frame of the others
  std::optional<Isometry3d> initial;  ///< T_base_target guess, used when terra does not run
  /// The clocks' offset when it is known (t_base = t_target + offset; 0 for synchronised
  /// clocks): every stage reads b's timestamps moved onto a's clock, HOTS does not estimate an
  /// offset (nor check one) and the result reports this one. Unset: HOTS estimates it.
  std::optional<double> time_offset_s;
  CalibrateProgress progress;  ///< optional
};

}  // namespace ulc
