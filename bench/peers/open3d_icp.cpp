// Open3D's point-to-plane ICP (pipelines::registration::RegistrationICP with
// TransformationEstimationPointToPlane and its Geman-McClure kernel), a peer of
// ulc::register_point_to_plane in bench_peers. Open3D parallelises with OpenMP.
#include <omp.h>

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/RobustKernel.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>

#include "peers/peer_icp.hpp"

namespace ulc_peers {
namespace {

namespace reg = open3d::pipelines::registration;

class Open3dPeer : public PeerIcp {
 public:
  std::string name() const override { return "Open3D 0.16"; }
  std::string method() const override {
    return "RegistrationICP, TransformationEstimationPointToPlane(GMLoss)";
  }
  void set_clouds(const std::vector<Eigen::Vector3d>& source,
                  const std::vector<Eigen::Vector3d>& target,
                  const std::vector<Eigen::Vector3d>& target_normals,
                  const IcpSettings& settings) override {
    settings_ = settings;
    source_.points_ = source;
    target_.points_ = target;
    target_.normals_ = target_normals;
    raw_target_.points_ = target;
  }
  IcpOutcome align(const Eigen::Isometry3d& initial) override { return run(target_, initial); }
  IcpOutcome normals_and_align(const Eigen::Isometry3d& initial) override {
    open3d::geometry::PointCloud target = raw_target_;
    target.EstimateNormals(
        open3d::geometry::KDTreeSearchParamKNN(static_cast<int>(settings_.normal_k)));
    return run(target, initial);
  }
  void set_threads(int threads) override { omp_set_num_threads(threads); }

 private:
  IcpOutcome run(const open3d::geometry::PointCloud& target, const Eigen::Isometry3d& initial) {
    // Open3D's GMLoss weighs r by k / (k + r^2)^2: k = scale^2 gives our
    // Geman-McClure weight (1 + (r / scale)^2)^-2 up to a constant factor.
    const auto kernel =
        std::make_shared<reg::GMLoss>(settings_.kernel_scale * settings_.kernel_scale);
    // Open3D stops on relative changes of fitness and RMSE, not on the step: 1e-6 is its
    // default and its own documentation's choice.
    const reg::ICPConvergenceCriteria criteria(1e-6, 1e-6, settings_.max_iterations);
    const auto r =
        reg::RegistrationICP(source_, target, settings_.gate, initial.matrix(),
                             reg::TransformationEstimationPointToPlane(kernel), criteria);
    IcpOutcome out;
    out.pose.matrix() = r.transformation_;
    out.iterations = -1;  // Open3D 0.16's result does not report it
    out.converged = r.fitness_ > 0.0;
    return out;
  }

  IcpSettings settings_;
  open3d::geometry::PointCloud source_, target_, raw_target_;
};

}  // namespace

std::unique_ptr<PeerIcp> make_open3d_peer() {
  return std::make_unique<Open3dPeer>();
}

}  // namespace ulc_peers
