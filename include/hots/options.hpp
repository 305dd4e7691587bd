// The options of every HOTS stage (hots.hpp's RefineOptions and the options of the
// hierarchy, window BA, plane extraction, cross links, sparse LM, time synchronisation and
// whole-sequence extrinsic it holds), with their defaults.
//
// Separate from the algorithms' headers so that a file that only sets options (a user's file
// holding ulc::CalibrateOptions) includes this light header, which needs only the standard
// library, Eigen/Core and Eigen/Geometry, instead of the stages' inline functions, TBB and
// Eigen's solvers (docs/design.md). Each algorithm header includes it; the structs' meaning is
// documented with the algorithm that uses them.
#pragma once

#include <cstddef>
#include <vector>

#include "ulc/core/registration_types.hpp"
#include "ulc/core/robust_kernel.hpp"

namespace hots {

struct PlaneExtractionOptions {
  double voxel_size = 1.0;        ///< root voxel edge, m
  int max_depth = 2;              ///< octree splits below a root voxel
  std::size_t min_points = 10;    ///< per plane, all frames together
  std::size_t min_frames = 2;     ///< frames seeing a plane
  double max_eigen_ratio = 0.05;  ///< lambda_0 / lambda_1 at most this
  double max_distance = 0.12;     ///< largest distance of a point to the plane, m
};

struct PlaneEvaluationOptions {
  /// Relative gap: degenerate when lambda_1 - lambda_0 <= min_gap * (trace + tiny).
  double min_gap = 1e-9;
};

struct WindowBaOptions {
  PlaneExtractionOptions planes;
  /// Plane extractions: after the first converges, planes are extracted again at the refined
  /// poses (cells that mixed two surfaces at a poor start separate) and LM runs again.
  int rounds = 2;
  int max_iterations = 30;        ///< LM steps per round
  double initial_damping = 1e-4;  ///< mu_0 = this * max diagonal of the Hessian
  double step_tolerance = 1e-8;   ///< stop when every step entry (m, rad) is below this
  double cost_tolerance = 1e-10;  ///< stop when an accepted step lowers the cost by less (rel.)
  std::size_t min_planes = 10;
  PlaneEvaluationOptions evaluation;
  std::size_t grain = 32;  ///< planes per parallel chunk (fixed: results never depend on it)
};

struct HierarchyOptions {
  std::size_t window = 5;
  int layers = 3;
  /// One plane extraction per window, in 2 m root voxels: the odometry's poses are already
  /// within centimetres, so the second extraction (window_ba.hpp, rounds) halved the
  /// hierarchy's speed and 1 m roots (more, smaller planes) cost a third more, for nothing
  /// measurable on the 64-32 and 64-horizon drives (docs/BENCHMARKS.md, bench_hots).
  WindowBaOptions ba = hots_window_ba();
  double submap_voxel = 0.2;  ///< m

  static WindowBaOptions hots_window_ba() {
    WindowBaOptions o;
    o.rounds = 1;
    o.planes.voxel_size = 2.0;
    return o;
  }
  /// Floor of the BA noise estimate (m): a near-perfect window does not dominate the graph.
  double min_sigma = 1e-3;
  /// Layer 0 with continuous-time sweeps (sweep_ba.hpp) when the caller gives the frames'
  /// parts: each window's last sweep ends at the next frame's pose (a variable of the window,
  /// not returned) when end_knot, else it stays as deskewed.
  bool end_knot = true;
  /// With end_knot: the window's estimate of the next frame's pose also becomes a factor (from
  /// the window's anchor to that frame, its marginal information): the windows of layer 0 tie
  /// to each other directly.
  bool end_knot_factor = false;
  /// Parts per sweep for the continuous-time layer 0 (refine() splits the frames); 1: rigid.
  /// Two by default: on the 60 s 64-32 drives the sweeps lower HOTS's trajectory error
  /// (docs/experiments/continuous_time_sweeps.md; current figures: docs/BENCHMARKS.md, "Sweeps
  /// and bridges by default"). The parts are views into the thinned frames (point_span.hpp),
  /// not a copy of them.
  int sweep_parts = 2;
};

struct CrossLinkOptions {
  int min_layer = 0;  ///< layers min_layer .. top are linked
  /// At layer 0, every n-th a frame: one link per window, as the layers above have. Every frame
  /// (1) cost 2.5x the link time on bench_hots 64-32 for no better extrinsic.
  std::size_t layer0_stride = 5;
  double source_voxel = 0.5;  ///< m, b's cloud (registered points) thinning; 0: none
  double target_voxel = 0.5;  ///< m, a's cloud (planes) thinning; 0: none
  double gate = 1.0;          ///< first registration stage's gate, m
  double min_inlier_ratio = 0.3;
  /// A converged registration under min_inlier_ratio counts as a weak link when its inlier
  /// ratio reaches this: reported (CrossLinkStats), not used.
  double weak_inlier_ratio = 0.1;
  /// When too few links are kept to judge the extrinsic, take a second look: each link's inlier
  /// ratio over b's points within a's reach (the farthest of a's points from its anchor), which
  /// a's surfaces could hold at all. A Tele-15 or an Avia sees far beyond a short-range base
  /// (an OS0-128's 50 m), and its points there say nothing of the extrinsic
  /// (docs/experiments/cross_links_within_reach.md).
  bool second_look_within_reach = true;
  double min_sigma = 0.01;                                     ///< m
  double agree_rotation_rad = 1.0 * 3.14159265358979 / 180.0;  ///< see the conventions
  double agree_translation_m = 1.0;
  ulc::PlaneCloudOptions planes;
};

struct SparseLmOptions {
  int max_iterations = 50;
  double initial_damping = 1e-4;  ///< mu_0 (relative to diag(H))
  double step_tolerance = 1e-9;   ///< m and rad
  double cost_tolerance = 1e-12;  ///< relative cost decrease of an accepted step
  double min_diagonal = 1e-9;     ///< diag(H) entries below this are lifted (in the damping)
  std::size_t grain = 256;        ///< factors per parallel task (fixed)
};

struct TimeSyncOptions {
  double centre_s = 0.0;        ///< the search is centred here
  double search_periods = 1.0;  ///< half width, in a's frame periods
  int grid_samples = 41;        ///< coarse scan before the golden section (>= 3)
  double tolerance_s = 1e-5;    ///< golden-section stop (interval width)
  double rotation_scale_m = 10.0;
  std::size_t min_pairs = 10;
  /// The found offset replaces centre_s only when n (spread(centre) - spread(dt*)) exceeds this
  /// many times spread(dt*): on a drive at nearly constant velocity the curve is flat and its
  /// minimum is decided by pose noise (fitting one parameter to pure noise lowers n * spread by
  /// about one per-pair variance), which would turn noise into a biased translation.
  double min_significance = 4.0;
};

struct SequenceExtrinsicOptions {
  bool enabled = true;
  int target_layer = 1;          ///< the base's submaps of this layer (clamped to the hierarchy)
  double source_voxel = 0.8;     ///< m, each target frame's thinning
  double target_voxel = 0.3;     ///< m, each base submap's thinning
  std::size_t frame_stride = 4;  ///< every n-th target frame (2.5 per second at 10 Hz)
  /// ... but a shorter stride (down to every frame) while the stride would leave fewer frames
  /// than this: the covariance is a delete-one-frame jackknife, and an estimate of 6 directions
  /// from G frames is widened by Hotelling's T^2 (ulc/core/small_sample.hpp): 1.95 in variance
  /// at G = 25, 387 at G = 8 (a 3 s drive at stride 4).
  std::size_t min_frames = 25;
  ulc::PlaneCloudOptions planes;
  /// Coarse to fine from HOTS's start (millimetres to a few centimetres away).
  std::vector<ulc::RegistrationOptions> stages = default_stages();
  bool estimate_time_offset = true;
  double time_window_s = 0.05;           ///< |dt - start| beyond this: dt not adopted
  double max_time_sigma_s = 2e-3;        ///< dt adopted only when pinned down this well
  std::size_t time_cluster_frames = 10;  ///< consecutive target frames sharing their errors
  double derivative_step_s = 1e-3;       ///< central difference of the trajectory
  double min_condition = 1e-6;           ///< eigen directions (scaled) skipped below this
  bool check_time_offset = true;         ///< the halves' trust check (sequence_offset.hpp)
  /// s: the halves' offsets, and the kept offset and the whole solve's, must agree this well
  /// (5 ms is 5 cm of translation at 10 m/s).
  double max_time_disagreement_s = 5e-3;
  /// The check fails first when dt's information that a change of C cannot explain
  /// (time_observability) is below this share: 0.1 is a variance inflation of 10, the usual
  /// threshold of serious collinearity (60 s drives: 0.2-0.5; 6 s drives: 0.001-0.01).
  double min_time_observability = 0.1;

  static std::vector<ulc::RegistrationOptions> default_stages() {
    ulc::RegistrationOptions coarse, fine;
    coarse.max_correspondence_distance = 0.5;
    coarse.kernel = ulc::RobustKernel::geman_mcclure(0.1);
    coarse.max_iterations = 8;
    coarse.max_solver_iterations = 3;
    coarse.translation_tolerance = 1e-3;
    coarse.rotation_tolerance = 1e-4;
    fine.max_correspondence_distance = 0.25;
    fine.kernel = ulc::RobustKernel::geman_mcclure(0.03);
    fine.max_iterations = 8;
    fine.max_solver_iterations = 3;
    fine.translation_tolerance = 5e-5;
    fine.rotation_tolerance = 5e-6;
    return {coarse, fine};
  }
};

struct RefineOptions {
  /// m, per-frame downsampling before the BA: the BA's cost is per plane, not per point, and
  /// 0.2 m keeps the planes (the hierarchy's cells are 0.5 m and up) and cut the hierarchy's
  /// time by a quarter against 0.1 m on bench_hots 64-32.
  double frame_voxel = 0.2;
  HierarchyOptions hierarchy;
  CrossLinkOptions links;
  SparseLmOptions solver;
  double extrinsic_sigma_m = 0.05;     ///< per tie
  double extrinsic_sigma_rad = 0.003;  ///< per tie
  double link_huber = 3.0;             ///< whitened units
  /// The hierarchy's top-layer submaps share no BA window, so nothing in the graph would tie
  /// one to the next. With boundary_bridges a window BA over the top layer's members on both
  /// sides of each boundary ties them (boundary_bridges.hpp). Where there is no usable bridge,
  /// with boundary_registration each submap is registered to the next
  /// (boundary_links.hpp, Huber link_huber); where that fails, or without it, the odometry's
  /// step across the boundary (last frame of a submap to the first of the next) becomes a
  /// factor with these standard deviations. sigma <= 0 and no registration: no boundary factors.
  bool boundary_bridges = true;
  double bridge_huber = 0.0;  ///< whitened units; 0: a bridge's factors are plain least squares
  bool boundary_registration = true;
  /// m, the boundary registration's crop around the boundary (boundary_links.hpp); 0: none.
  double boundary_radius_m = 0.0;
  double boundary_sigma_m = 0.02;
  double boundary_sigma_rad = 0.002;
  /// Trust (see the conventions): agreeing cross links >= max(min_cross_links,
  /// min_cross_link_ratio * attempted); min_cross_link_ratio <= 0 turns the check off.
  double min_cross_link_ratio = 0.03;
  std::size_t min_cross_links = 3;
  double time_offset_s = 0.0;  ///< initial clock offset estimate (centre of the search)
  bool synchronise_time = true;
  TimeSyncOptions time_sync;  ///< centre_s is replaced by time_offset_s
  int passes = 2;
  /// The last step: C and dt from every target frame against the base's submaps
  /// (sequence_extrinsic.hpp), started from the time synchronisation's answer.
  SequenceExtrinsicOptions sequence;
};

}  // namespace hots
