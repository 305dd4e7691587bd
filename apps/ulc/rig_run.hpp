// A rig calibration as `ulc calibrate` runs it, shared with the Python module (python/): the
// LiDARs' frames read from their sources on demand (as many as the stages need; a drive longer
// than the budget surveyed and its best stretch used, drive_selection.hpp), calibrate_rig run in
// a task arena of the asked size, and the result file's entries made from its outcome. The
// command line and Python therefore write the same result file for the same input.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lidar_input.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/rig.hpp"
#include "pipeline/selection.hpp"
#include "ulc/io/result_file.hpp"

namespace ulc::app {

/// The calibration's choices as the command line words them (`ulc calibrate --help`).
struct CalibrateChoices {
  std::string stages = "terra,jeep,hots";           ///< --stages
  std::optional<std::string> initial;               ///< --initial; allowed only without terra
  bool synced_clocks = false;                       ///< --synced-clocks
  std::optional<double> time_offset_s;              ///< --time-offset, within [-1, 1] s
  std::size_t frames = jeep::JeepOptions{}.frames;  ///< --frames
  HotsOdometry odometry = HotsOdometry::automatic;  ///< --base-odometry, --joint-odometry
};

/// The pipeline's options; UsageError (worded as the command line's) before any frame is read.
CalibrateOptions calibrate_options(const CalibrateChoices& choices);

/// Where the LiDARs' frames come from and what the rig does with them.
struct RigRequest {
  std::vector<LidarSpec> specs;  ///< the base first
  InputOptions input;
  std::size_t frame_index = 0;  ///< the first frame read of every LiDAR
  std::string initial;          ///< --initial: six numbers or a result file (stages without terra)
  bool route = true;            ///< calibrate failed targets through a calibrated one
  bool cycles = true;           ///< close the cycles (with two targets or more)
  double budget_s = SelectionOptions{}.budget_s;  ///< --budget; 0: the whole drive
  std::size_t threads = 0;                        ///< the survey's workers (0: TBB's default)
  bool quiet = true;                              ///< no survey progress on stderr
};

/// Every LiDAR's frames from frame_index, read on demand for the whole rig (routes and cycles
/// pair targets too); the base's are shared by all targets.
struct LoadedRig {
  std::optional<Selection> selection;  ///< when the drive was surveyed
  double budget_s = 0.0;               ///< the budget it was surveyed for
  std::vector<std::unique_ptr<LidarInput>> inputs;
  std::vector<StreamedFrames> frames;  ///< the base's first
  std::vector<RigLidar<FrameSource>> lidars;
};

/// Opens the sources (surveying a drive longer than the budget when HOTS runs and no --start /
/// --duration is given) and prepares the frames the stages need, read when they ask. Throws
/// UsageError or io::IoError.
LoadedRig load_rig(const RigRequest& request, const CalibrateOptions& options);

/// The rig's options as the command line sets them (options.frame_index applies to `lidars`).
RigOptions rig_options(const CalibrateOptions& options, bool route, bool cycles,
                       std::size_t lidar_count);

/// calibrate_rig in a task arena of `threads` workers (0: TBB's default), on frames read on
/// demand whose read errors are the caller's to check. UsageError for invalid input (names,
/// missing frames).
RigCalibration run_rig(const std::vector<RigLidar<FrameSource>>& lidars, const RigOptions& options,
                       std::size_t threads);
/// The same on the loaded sources, whose read errors it checks: io::IoError when a frame could
/// not be read (it reached the stages empty, so the result is not to be trusted).
RigCalibration run_rig(const LoadedRig& loaded, const RigOptions& options, std::size_t threads);

/// The result file's entries of a rig: one per target, in input order, and one per cycle.
/// `frame_index` is the absolute index of TERRA's frame, written into stages.terra; a surveyed
/// drive's choice goes into stages.selection.
io::ResultDocument rig_entries(const RigCalibration& rig, std::size_t frame_index,
                               const std::optional<Selection>& selection = std::nullopt,
                               double budget_s = 0.0);

}  // namespace ulc::app
