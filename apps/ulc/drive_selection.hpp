// The stretch of a long drive that `ulc calibrate` calibrates on (pipeline/selection.hpp): the
// base LiDAR surveyed, a stretch of --budget seconds chosen, and what was chosen and why for the
// result file (stages.selection).
#pragma once

#include "lidar_input.hpp"
#include "pipeline/selection.hpp"
#include "ulc/io/json_file.hpp"

namespace ulc::app {

/// Surveys `base`'s frames (a folder reads only the frames the survey uses; a recording is read
/// in order) and chooses the stretch. Throws io::IoError when a frame cannot be read.
Selection survey_drive(const LidarInput& base, const SelectionOptions& options, bool quiet);

/// stages.selection of the result file: the chosen stretch, why, and every candidate's scores.
io::Json selection_json(const Selection& s, double budget_s);

}  // namespace ulc::app
