// A rig calibration as `ulc calibrate` runs it, shared with the Python module (python/): the
// LiDARs' frames read from their sources (as many as the stages need), calibrate_rig run in a
// task arena of the asked size, and the result file's entries made from its outcome. The
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
#include "ulc/io/result_file.hpp"

namespace ulc::app {

/// The calibration's choices as the command line words them (`ulc calibrate --help`).
struct CalibrateChoices {
  std::string stages = "terra,jeep,hots";           ///< --stages
  std::optional<std::string> initial;               ///< --initial; allowed only without terra
  bool synced_clocks = false;                       ///< --synced-clocks
  std::optional<double> time_offset_s;              ///< --time-offset, within [-1, 1] s
  std::size_t frames = jeep::JeepOptions{}.frames;  ///< --frames
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
};

/// Every LiDAR's frames from frame_index, held for the whole rig (routes and cycles pair targets
/// too); the base's are shared by all targets.
struct LoadedRig {
  std::vector<std::unique_ptr<LidarInput>> inputs;
  std::vector<LoadedFrames> frames;  ///< the base's first
  std::vector<RigLidar<FloatFrames>> lidars;
};

/// Opens the sources and reads the frames the stages need. Throws UsageError or io::IoError.
LoadedRig load_rig(const RigRequest& request, const CalibrateOptions& options);

/// The rig's options as the command line sets them (options.frame_index applies to `lidars`).
RigOptions rig_options(const CalibrateOptions& options, bool route, bool cycles,
                       std::size_t lidar_count);

/// calibrate_rig in a task arena of `threads` workers (0: TBB's default). UsageError for
/// invalid input (names, missing frames).
RigCalibration run_rig(const std::vector<RigLidar<FloatFrames>>& lidars, const RigOptions& options,
                       std::size_t threads);

/// The result file's entries of a rig: one per target, in input order, and one per cycle.
/// `frame_index` is the absolute index of TERRA's frame, written into stages.terra.
io::ResultDocument rig_entries(const RigCalibration& rig, std::size_t frame_index);

}  // namespace ulc::app
