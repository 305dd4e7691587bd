// PCL's point-to-plane ICP (IterativeClosestPointWithNormals, linear least squares), a peer
// of ulc::register_point_to_plane in bench_peers. Single-threaded: PCL's ICP has no threads.
// PCL has no robust kernel in ICP: its outliers are only what the gate rejects.
#include <cmath>

#include <pcl/features/normal_3d.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/search/kdtree.h>

#include "peers/peer_icp.hpp"

namespace ulc_peers {
namespace {

using Cloud = pcl::PointCloud<pcl::PointNormal>;

/// PCL keeps the iteration count protected; this only reads it.
class Icp
    : public pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal, double> {
 public:
  int iterations() const { return this->nr_iterations_; }
};

Cloud::Ptr to_pcl(const std::vector<Eigen::Vector3d>& points,
                  const std::vector<Eigen::Vector3d>* normals) {
  Cloud::Ptr cloud(new Cloud);
  cloud->reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    pcl::PointNormal p;
    p.x = static_cast<float>(points[i].x());
    p.y = static_cast<float>(points[i].y());
    p.z = static_cast<float>(points[i].z());
    const Eigen::Vector3d n = normals ? (*normals)[i] : Eigen::Vector3d::Zero();
    p.normal_x = static_cast<float>(n.x());
    p.normal_y = static_cast<float>(n.y());
    p.normal_z = static_cast<float>(n.z());
    cloud->push_back(p);
  }
  return cloud;
}

class PclPeer : public PeerIcp {
 public:
  std::string name() const override { return "PCL " PCL_VERSION_PRETTY; }
  std::string method() const override {
    return "IterativeClosestPointWithNormals (point-to-plane LLS), gate only, no kernel";
  }
  void set_clouds(const std::vector<Eigen::Vector3d>& source,
                  const std::vector<Eigen::Vector3d>& target,
                  const std::vector<Eigen::Vector3d>& target_normals,
                  const IcpSettings& settings) override {
    settings_ = settings;
    source_ = to_pcl(source, nullptr);
    target_ = to_pcl(target, &target_normals);
    raw_target_ = to_pcl(target, nullptr);
  }
  IcpOutcome align(const Eigen::Isometry3d& initial) override { return run(target_, initial); }
  IcpOutcome normals_and_align(const Eigen::Isometry3d& initial) override {
    Cloud::Ptr target(new Cloud(*raw_target_));
    pcl::NormalEstimation<pcl::PointNormal, pcl::PointNormal> estimation;
    pcl::search::KdTree<pcl::PointNormal>::Ptr tree(new pcl::search::KdTree<pcl::PointNormal>);
    estimation.setSearchMethod(tree);
    estimation.setKSearch(static_cast<int>(settings_.normal_k));
    estimation.setInputCloud(target);
    estimation.compute(*target);  // fills normal_x..z and curvature, keeps xyz
    Cloud::Ptr finite(new Cloud);
    for (const auto& p : *target)
      if (std::isfinite(p.normal_x)) finite->push_back(p);
    return run(finite, initial);
  }
  void set_threads(int) override {}

 private:
  IcpOutcome run(const Cloud::Ptr& target, const Eigen::Isometry3d& initial) {
    Icp icp;
    icp.setInputSource(source_);
    icp.setInputTarget(target);  // the target's kd-tree is built inside align()
    icp.setMaxCorrespondenceDistance(settings_.gate);
    icp.setMaximumIterations(settings_.max_iterations);
    // The same stopping rule as ours: a step below both tolerances (PCL compares the squared
    // translation and the cosine of the rotation angle).
    icp.setTransformationEpsilon(settings_.translation_tolerance * settings_.translation_tolerance);
    icp.setTransformationRotationEpsilon(std::cos(settings_.rotation_tolerance));
    icp.setEuclideanFitnessEpsilon(0.0);
    Cloud aligned;
    icp.align(aligned, initial.matrix());
    IcpOutcome out;
    out.pose.matrix() = icp.getFinalTransformation();
    out.converged = icp.hasConverged();
    out.iterations = icp.iterations();
    return out;
  }

  IcpSettings settings_;
  Cloud::Ptr source_, target_, raw_target_;
};

}  // namespace

std::unique_ptr<PeerIcp> make_pcl_peer() {
  return std::make_unique<PclPeer>();
}

}  // namespace ulc_peers
