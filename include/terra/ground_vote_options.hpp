// The ground vote's options and result (ground_vote.hpp), apart from the algorithm so that the
// pipeline's options stay light.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "terra/plane_fit.hpp"
#include "ulc/core/types.hpp"

namespace terra {

struct GroundVoteOptions {
  double voxel = 0.5;             ///< m, the fine grid's voxel and translation step
  double max_translation = 4.0;   ///< m, the lever arm searched along each ground axis
  double max_range = 100.0;       ///< m, horizontal, of the points that vote or are voted on
  double min_height = 0.3;        ///< m above the ground: lower points are the ground itself
  double max_height = 10.0;       ///< m above the ground
  double coarse_step_deg = 1.0;   ///< yaw step of the coarse pass
  double coarse_voxel = 1.0;      ///< m, its grid's voxel and translation step
  double fine_step_deg = 0.25;    ///< yaw step of the refinement
  std::size_t target_planes = 3;  ///< target ground candidates, largest first
  /// A target plane is a ground candidate only when the target sits within this height of the
  /// base's above it (two LiDARs of one vehicle: the simulated rigs' mounts differ by up to
  /// 0.65 m). A wall taken for the ground puts the sensor its distance from the wall "above"
  /// it: 2.6-55 m in the 16-tele windows where such a wall won the vote with a wrong yaw.
  double max_height_difference = 1.0;
  std::size_t min_plane_points = 50;
  std::size_t peaks_per_plane = 4;
  double peak_separation_deg = 10.0;
  std::size_t min_points = 100;   ///< target voxels above the ground for a confident answer
  std::size_t max_points = 1500;  ///< bound on the votes per rotation (cost)
  double margin_separation_deg = 20.0;
  /// Measured (docs/experiments/terra_ground_vote.md, 2 s windows): right answers had
  /// margins of 1.65-4.4 on 64-tele; the 16-tele windows, where the VLP-16's map is too sparse
  /// to tell, 1.02-1.34 whether right or wrong.
  double min_margin = 1.5;
  /// The winner's share of votes that landed, at least: 16-tele's VLP-16 map is so sparse
  /// that a wrong yaw won with 5 % of 131 votes (right answers: 12-66 %).
  double min_score = 0.1;
  /// deg, the base's elevation gap between its rings (ring_gap.hpp; 0: a dense base). A
  /// VLP-16's 2 deg leave 3.5 m between rings at 100 m, where a Tele-15's returns fall between
  /// them: at the truth 9-44 % of its votes landed, at the street's twin as many. Half the gap
  /// is filled up and down from each ring (the whole gap, or 1 deg over a denser base, lost
  /// windows): docs/experiments/terra_ground_vote.md, "A sparse base's rings".
  double base_ring_gap_deg = 0.0;
  /// Scoring a pose found on another frame (pose_share in ground_vote.hpp, the window's pooled
  /// vote): the target ground it turns within pose_tilt_deg of the base's is voted with yaws
  /// within one coarse step and shifts within pose_shift_voxels voxels of the pose's.
  double pose_tilt_deg = 5.0;
  std::size_t pose_shift_voxels = 2;
  PlaneFitOptions plane;
};

/// A pose of the target in the base's frame: R_base_target, t_base_target.
struct GroundPose {
  ulc::Mat3d rotation = ulc::Mat3d::Identity();
  ulc::Vec3d translation = ulc::Vec3d::Zero();
};

struct GroundVoteResult {
  bool ok = false;                                ///< a confident answer (see the conventions)
  std::string reason;                             ///< why not, when not ok
  ulc::Mat3d rotation = ulc::Mat3d::Identity();   ///< R_base_target
  ulc::Vec3d translation = ulc::Vec3d::Zero();    ///< t_base_target
  double score = 0.0;                             ///< share of the votes that landed
  double margin = 0.0;                            ///< see the conventions (infinity when no rival)
  std::size_t points = 0;                         ///< target voxels that voted for the answer
  std::size_t target_plane = 0;                   ///< which of the target's planes was its ground
  double base_height = 0.0, target_height = 0.0;  ///< m, each sensor above its ground
  double base_ring_gap_deg = 0.0;  ///< the options' gap the base's rings were filled by
  std::vector<GroundPose> peaks;   ///< every refined peak, the answer among them
};

}  // namespace terra
