// The options and the report of the stillness check: did the rig stand still for the whole
// recording? (pipeline/stillness.hpp), and what a still rig's JEEP stacks (parked_stack.hpp).
// Light: no algorithm.
#pragma once

#include <cstddef>
#include <string>

namespace ulc {

struct StillnessOptions {
  bool enabled = true;
  /// Base frames compared with the first, spread evenly over the frames HOTS would use (the
  /// last among them): a rig that drove and came back to its spot is caught at the others.
  std::size_t samples = 8;
  /// Voxel edge (m) both frames are thinned to before the registration.
  double voxel = 0.3;
  /// Still: every compared frame lies within this of the first (m, deg). A parked rig's frames
  /// register to each other within millimetres; one that moved 5 cm in a whole recording gives
  /// HOTS's odometry nothing to use either.
  double max_travel_m = 0.05;
  double max_turn_deg = 0.3;
  /// A registration that leaves a direction nearly free (a tunnel, a straight road) cannot tell
  /// a standing rig from one moving along that direction: below this condition (the scaled
  /// Hessian's lambda_min / lambda_max, registration_conditioning.hpp) the rig is not called
  /// still. StageTuning::min_odometry_condition's value, for the same reason.
  double min_condition = 0.03;
  /// ... and one whose points mostly found no surface of the first frame (a large move) neither.
  double min_inlier_ratio = 0.5;
};

/// What a rig found still gives JEEP (pipeline/parked_stack.hpp).
struct ParkedStackOptions {
  /// Frames per LiDAR stacked into JEEP's one frame pair (1, or 0: the first frame alone).
  std::size_t frames = 10;
};

/// What the check found (stages.hots.stillness).
struct StillnessReport {
  bool still = false;
  /// The registrations could tell (converged, conditioned, overlapping); when not, `still` is
  /// false and HOTS judges the drive as it would any other.
  bool decided = false;
  /// Base frames registered to the first, up to the one that ended the check.
  std::size_t frames_compared = 0;
  double span_s = 0.0;            ///< seconds from the first frame to the last compared
  double max_travel_m = 0.0;      ///< the largest displacement found from the first frame
  double max_turn_deg = 0.0;      ///< the largest rotation found from the first frame
  double min_condition = 0.0;     ///< the weakest registration's condition
  double min_inlier_ratio = 0.0;  ///< the weakest registration's inlier ratio
  std::string reason;             ///< why the rig counts as still or not, in one sentence
};

}  // namespace ulc
