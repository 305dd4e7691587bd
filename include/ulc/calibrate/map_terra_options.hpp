// The options of TERRA on local maps (map_terra.hpp) and what it reports of each map, apart
// from the algorithm so that ulc/calibrate/options.hpp and pair_calibration.hpp stay light.
#pragma once

#include <cstddef>
#include <string>

#include "jeep/options.hpp"

namespace ulc {

/// Which frame of the window the map is expressed in.
enum class MapAnchor { first_frame, last_frame };

struct MapTerraOptions {
  /// The window's LAST frame (measured, bench_terra --maps): a map made ahead of its anchor
  /// frame adds no direction to a narrow FoV driving forward (whatever it sees later lies
  /// inside its first cone, seen from the first frame: a Tele-15 map over 2 s filled 58 cells
  /// against its frame's 50), while the frames behind the last one saw what is now beside it
  /// (635 cells over 2 s, 2150 over 5 s).
  MapAnchor anchor = MapAnchor::last_frame;
  double window_s = 5.0;        ///< seconds of each LiDAR's frames from frame `first` on
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
  jeep::OdometryOptions odometry;   ///< each LiDAR's own odometry over the window
  /// How each frame enters its map: the range gate keeps the vehicle out (min_range) but lets
  /// far returns in (TERRA's mask only compares cells beyond d1 = 20 m); the map voxel is the
  /// first thinning, before the stack's.
  jeep::ScanOptions scan = default_scan();

  static jeep::ScanOptions default_scan() {
    jeep::ScanOptions s;
    s.min_range = 2.0;
    s.max_range = 500.0;
    s.map_voxel = 0.2;
    s.registration_voxel = 0.2;
    return s;
  }
};

/// One LiDAR's local map and how it was made.
struct LocalMapStats {
  std::size_t frames = 0;          ///< frames in the window (stacked into the map)
  std::size_t stacked_points = 0;  ///< points before the stack's thinning
  std::size_t points = 0;          ///< map points given to TERRA
  double voxel_used = 0.0;         ///< m, the stack's thinning voxel after fitting max_points
  std::string odometry_status;     ///< jeep::to_string(OdometryStatus)
  std::string odometry_reason;
  std::size_t odometry_failed_steps = 0;
  double seconds = 0.0;  ///< odometry and map building
};

}  // namespace ulc
