// `ulc calibrate --merged-cloud fused.pcd`: every LiDAR's frame moved into the base frame by
// its calibrated extrinsic, in one binary PCD with PCL's packed `rgb` field (one colour per
// LiDAR, palette order: base first) and a `lidar` field (0 = base, 1.. = targets as given), so
// any viewer (pcl_viewer, CloudCompare) shows the LiDARs apart.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace ulc::app {

struct FusedPart {
  std::vector<Eigen::Vector3f> points;  ///< in the LiDAR's own frame
  Eigen::Isometry3d T_base_lidar = Eigen::Isometry3d::Identity();
};

/// Throws ulc::io::IoError when the file cannot be written.
void write_fused_cloud(const std::string& pcd, const std::vector<FusedPart>& parts);

}  // namespace ulc::app
