// The options of TERRA's input (single frames or local maps, map_terra.hpp) and what it reports
// of each map, apart from the algorithm so that pipeline/options.hpp and
// pair_calibration.hpp stay light.
#pragma once

#include <cstddef>
#include <string>

#include "odometry/options.hpp"
#include "odometry/status.hpp"
#include "terra/ground_vote_options.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// Which frame of the window the map is expressed in.
enum class MapAnchor { first_frame, last_frame };

/// The motion frame (motion_frame.hpp): the rotation that lines up the two LiDARs' ground planes
/// and their directions of travel over the map window. Not in the paper. Why: a narrow field
/// of view shares too few lattice cells for eq:feature_dis to tell the true rotation from a
/// chance match (a Tele-15 frame: 8-14 cells at the truth), but every LiDAR of a moving
/// vehicle sees the road under it and moves the way the vehicle does. Measured (bench_terra
/// --windows, docs/experiments/terra_motion_frame.md): the ground normals agree with the truth
/// within 1 deg, the directions of travel within 0.1-11 deg (the narrow LiDAR's own odometry).
struct MotionFrameOptions {
  bool enabled = true;
  double min_travel_m = 3.0;  ///< each LiDAR's travel over the window, at least
  /// |l_a - l_b| / max(l_a, l_b) at most: the two odometries agree. A narrow field of view
  /// looking along the travel can slip; measured on 64-tele (30 windows of 4 s), travels
  /// that differ by more than 3 % point up to 40 deg off, those within 3 % within 6 deg but
  /// one.
  double max_travel_mismatch = 0.03;
  double max_travel_tilt_deg = 10.0;   ///< a ground candidate holds the travel within this
  std::size_t planes = 4;              ///< largest planes of each map considered
  std::size_t min_plane_points = 200;  ///< a plane with fewer inliers is not considered
  /// Two planes are the same surface when, with the candidate rotation, their normals agree
  /// within plane_match_deg and their distances to the two sensors within plane_match_m (the
  /// mounts' offset along the normal: the ground's is their height difference).
  double plane_match_deg = 5.0;
  double plane_match_m = 2.0;
  /// A search answer within this of the motion frame's rotation is kept (the paper's answer
  /// where it works); one farther off is overruled. Wider than the motion frame's own errors
  /// (up to 11 deg measured), so a right answer is never overruled.
  double agree_deg = 15.0;
  /// The same when the maps' answer is the ground vote's: its right answers lie within
  /// 0.1-3 deg of the truth (a few 5-8 deg), so a search answer 10-15 deg off no longer stands
  /// beside it (bench_terra --windows, 32-avia: such answers kept under 15 deg failed 5 of 50
  /// windows; docs/experiments/terra_ground_vote.md).
  double vote_agree_deg = 5.0;
  /// The threshold for a report's method (the ground vote's or the ground and travel's).
  double agree_for(const std::string& method) const {
    return method == "ground vote" ? vote_agree_deg : agree_deg;
  }
  /// The ground vote (terra/ground_vote.hpp: a target frame against the base's map, both
  /// levelled on their ground, yaw and lever arm voted for; vote_frames of them tallied,
  /// pipeline/window_vote.hpp). When it is confident
  /// its rotation is the maps' answer, ahead of the ground and travel: it needs no travel and
  /// no target odometry. Measured (bench_terra --windows, 2 s, seeds 1 and 2;
  /// docs/experiments/terra_ground_vote.md).
  bool ground_vote = true;
  terra::GroundVoteOptions vote;
  /// Target frames voted, evenly spaced over the window, each against the base's map at the
  /// base frame nearest it in time; the answer most confident votes back (window_vote.hpp,
  /// which cites the measurement). 1: the anchor frame alone.
  std::size_t vote_frames = 3;
  /// Target frames voted, evenly spaced the same way (vote_frames among them), where none of
  /// the first vote_frames is sure: a narrow LiDAR facing open ground in some frames of the
  /// window. A window whose sure frames conflict keeps its first round (five frames turned
  /// one such 16-tele window of seed 2 into a sure wrong answer). 16-tele, 2 s windows, 50 per
  /// seed: 82 / 84 % within 10 deg against 82 / 78 %, the other pairs as before
  /// (docs/experiments/terra_ground_vote.md, "More frames where none is sure"). 0 or at most
  /// vote_frames: no second round.
  std::size_t unsure_vote_frames = 5;
  /// The votes also pooled (window_vote.hpp: every frame's peaks scored on every frame,
  /// against the base's surfaces and the free space its nearest raw frame saw); the pool
  /// answers where the tally of the frames' own answers is unsure, and vetoes a sure tally it
  /// contradicts. false: the tally alone. 16-tele, 2 s windows, 50 per seed: 70 / 74 % within
  /// 10 deg against 66 / 68 % (docs/experiments/terra_ground_vote.md, "Pooling the window's
  /// frames").
  bool pool_votes = true;
  /// Where the pooled vote is unsure and the ground and travel refused, the pool's best pose
  /// (at least vote.min_score of its votes landing) is the maps' rotation, method "unsure
  /// ground vote" (map_terra.hpp, stand_in_unsure_vote); false: the map search answers there.
  /// 16-tele, 2 s windows, 50 per seed: 82 / 78 % within 10 deg against 70 / 74 %; it cost
  /// 32-avia one window of seed 1 (a pool margin of 1.04, where the search was right):
  /// docs/experiments/terra_ground_vote.md, "An unsure pool as a guess".
  bool unsure_vote = true;
  /// The base's ring gap read off its window's first frame (terra/ring_gap.hpp) and filled in
  /// the vote's base map (GroundVoteOptions::base_ring_gap_deg, which cites the measurement);
  /// false: vote.base_ring_gap_deg as set.
  bool fill_base_rings = true;
};

/// What the motion frame found; `rotation` only when ok.
struct MotionReport {
  bool ok = false;
  std::string reason;                                 ///< why not, when not ok
  Mat3d rotation = Mat3d::Identity();                 ///< R_base_target lining up ground and travel
  double travel_base_m = 0.0, travel_target_m = 0.0;  ///< over the window
  std::size_t planes_base = 0, planes_target = 0;     ///< planes found in each map
  std::size_t planes_matched = 0;                     ///< surfaces both maps share under `rotation`
  /// The kept search's answer against `rotation` (deg), and whether the motion frame overruled
  /// it (then it is the first hypothesis).
  double search_off_deg = 0.0;
  bool used = false;
  /// Where `rotation` came from: "ground vote" (a confident vote), "ground and travel",
  /// "unsure ground vote" (MotionFrameOptions::unsure_vote), or empty when none answered.
  std::string method;
  terra::GroundVoteResult vote;  ///< the window's vote (window_vote.hpp), when it ran (vote_ran)
  bool vote_ran = false;
  std::size_t vote_frame = 0;       ///< the window frame whose vote `vote` is
  std::size_t votes = 0;            ///< frames voted
  std::size_t votes_confident = 0;  ///< of them confident
  std::size_t votes_agreeing = 0;   ///< confident and within vote_agree_deg of the answer
  bool vote_pooled = false;         ///< the answer pooled over the frames (pool_votes)
};

struct MapTerraOptions {
  /// The window's LAST frame (measured, bench_terra --maps): a map made ahead of its anchor
  /// frame adds no direction to a narrow FoV driving forward (whatever it sees later lies
  /// inside its first cone, seen from the first frame: a Tele-15 map over 2 s filled 58 cells
  /// against its frame's 50), while the frames behind the last one saw what is now beside it
  /// (635 cells over 2 s, 2150 over 5 s).
  MapAnchor anchor = MapAnchor::last_frame;
  /// Seconds of each LiDAR's frames from frame `first` on. 5 s: the map search's optima were
  /// measured at 5 s (the fallback hypotheses that find the pitched VLP-16 among them: at 4 s
  /// that rig fails), and a narrow field of view's own odometry slips less over a longer
  /// window, so the motion frame answers more often (64-tele, 30 windows: 18 answers at 2 s,
  /// 22 at 4 s, all but 2 within 10 deg). bench_terra --windows measures 2 s (issue 34's cap)
  /// and 5 s.
  double window_s = 5.0;
  std::size_t max_frames = 60;  ///< cap on the window's frames
  /// The search on maps uses this d1 (m) with the adaptive rule off: a map's cells are mostly
  /// near (what the frames behind saw is now close by), so few pass 20 m (a Tele-15 map over
  /// 5 s: 60-80 cells beyond 20 m) and the adaptive rule, reading that as a short-range
  /// LiDAR, drops d1 to the median range where the ground's symmetry wins. Measured on 64-tele
  /// (4 starts, 5 s): within 10 deg 0 of 4 with d1 = 20 m, 1 with 10 m, 2 with 7 m (a third
  /// at 10.9 deg). 0 keeps params' d1 and adaptive rule.
  double d1 = 7.0;
  double voxel = 0.2;               ///< m, thinning of the stacked map (doubled to fit max_points)
  std::size_t max_points = 300000;  ///< bound on each map's size
  odometry::OdometryOptions odometry;  ///< each LiDAR's own odometry over the window
  /// How each frame enters its map: the range gate keeps the vehicle out (min_range) but lets
  /// far returns in (TERRA's mask only compares cells beyond d1 = 20 m); the map voxel is the
  /// first thinning, before the stack's.
  odometry::ScanOptions scan = default_scan();
  MotionFrameOptions motion;  ///< the ground and travel of both maps (motion_frame.hpp)

  static odometry::ScanOptions default_scan() {
    odometry::ScanOptions s;
    s.min_range = 2.0;
    s.max_range = 500.0;
    s.map_voxel = 0.2;
    s.registration_voxel = 0.2;
    return s;
  }
};

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

/// The TERRA stage's choice of input (pipeline.hpp, terra_stage).
struct TerraSourceOptions {
  TerraSource source = TerraSource::automatic;
  /// automatic: the maps are tried only when each LiDAR has at least this many frames in the
  /// window from frame_index (a single frame, or a static snapshot, stays on frames) ...
  std::size_t maps_min_frames = 5;
  /// ... and the frame search failed or its eq:mask count at its answer is below this many
  /// cells. The map result is then kept when it succeeded with a larger mask count.
  std::size_t maps_below_mask = 100;
  MapTerraOptions maps;  ///< window, thinning and odometry of the local maps
};

/// One LiDAR's local map and how it was made.
struct LocalMapStats {
  std::size_t frames = 0;          ///< frames in the window (stacked into the map)
  std::size_t stacked_points = 0;  ///< points before the stack's thinning
  std::size_t points = 0;          ///< map points given to TERRA
  double voxel_used = 0.0;         ///< m, the stack's thinning voxel after fitting max_points
  odometry::OdometryStatus odometry_status = odometry::OdometryStatus::ok;
  std::string odometry_reason;
  std::size_t odometry_failed_steps = 0;
  double seconds = 0.0;  ///< odometry and map building
};

}  // namespace ulc
