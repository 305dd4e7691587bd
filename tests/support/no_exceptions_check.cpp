// Compiled with -fno-exceptions: every algorithm header must build this way (docs/design.md).
// Add each new algorithm header here.
#include "hots/hots.hpp"
#include "jeep/jeep.hpp"
#include "jeep/scan_scan.hpp"
#include "odometry/run_odometry.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/pipeline.hpp"
#include "pipeline/rig.hpp"
#include "terra/terra.hpp"
#include "ulc/core/cloud.hpp"
#include "ulc/core/kdtree.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/normal_equations.hpp"
#include "ulc/core/normals.hpp"
#include "ulc/core/parallel_reduce.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/rotation_mean.hpp"
#include "ulc/core/voxel.hpp"
#include "ulc/core/voxel_downsample.hpp"

// Instantiate the templates: a header can compile and still fail once instantiated.
template class ulc::KdTree<ulc::PointCloud<float>>;
template ulc::NormalsResult<float> ulc::estimate_normals(const ulc::PointCloud<float>&,
                                                         const ulc::NormalEstimationOptions&);
template ulc::VoxelDownsampleResult<double> ulc::voxel_downsample(const ulc::PointCloud<double>&,
                                                                  double);
template ulc::Vec3<double> ulc::so3_log(const Eigen::MatrixBase<ulc::Mat3<double>>&);
template ulc::PairCalibration ulc::calibrate_pair_in_place(
    const std::vector<ulc::PointCloud<float>>&, const std::vector<double>&,
    const std::vector<ulc::PointCloud<float>>&, const std::vector<double>&,
    const ulc::CalibrateOptions&);
template ulc::RigCalibration ulc::calibrate_rig(
    const std::vector<ulc::RigLidar<std::vector<ulc::PointCloud<float>>>>&, std::size_t,
    const ulc::RigOptions&);
