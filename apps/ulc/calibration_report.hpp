// `ulc calibrate --report report.png`: the fused cloud before (initial guess) and after
// calibration, top-down and from the side, so a person sees the walls line up. One colour per
// LiDAR (palette order: the base first, then the targets as given).
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace ulc::app {

struct ReportCloud {
  std::string name;
  std::vector<Eigen::Vector3f> points;                       ///< in the LiDAR's own frame
  Eigen::Isometry3d before = Eigen::Isometry3d::Identity();  ///< T_base_lidar, initial guess
  Eigen::Isometry3d after = Eigen::Isometry3d::Identity();   ///< T_base_lidar, calibrated
};

/// Writes the picture; throws ulc::io::IoError when the file cannot be written.
/// `clouds[0]` is the base (identity both times).
void write_calibration_report(const std::string& png, const std::vector<ReportCloud>& clouds,
                              double view_radius_m = 40.0);

}  // namespace ulc::app
