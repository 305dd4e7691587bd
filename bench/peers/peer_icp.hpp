// Other libraries' point-to-plane ICP, behind one interface, for bench_peers only (the library
// never depends on them). Each peer lives in its own translation unit, compiled only when
// CMake finds the library (bench/CMakeLists.txt); available_peers() lists those built in.
//
// Conventions: clouds cross the interface as double xyz (plus target normals) and are
// converted once, outside any timer; align() is what bench_peers times. `initial` and the
// returned pose map source points into the target frame.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ulc_peers {

struct IcpSettings {
  double gate = 1.0;          ///< m, max correspondence distance
  int max_iterations = 30;    ///< correspondence searches
  double kernel_scale = 0.1;  ///< m, Geman-McClure scale where the peer has robust kernels
  double translation_tolerance = 1e-4;  ///< m per iteration, as ulc::RegistrationOptions
  double rotation_tolerance = 1e-5;     ///< rad per iteration
  std::size_t normal_k = 10;            ///< neighbours for the peer's own normal estimation
};

struct IcpOutcome {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  int iterations = 0;  ///< as the peer reports it (-1: it does not say)
  bool converged = false;
};

class PeerIcp {
 public:
  virtual ~PeerIcp() = default;
  virtual std::string name() const = 0;
  /// What the peer's ICP is (kernel, estimator), for the table's notes.
  virtual std::string method() const = 0;
  /// Converts the clouds (untimed). `target_normals` are the normals to use in align().
  virtual void set_clouds(const std::vector<Eigen::Vector3d>& source,
                          const std::vector<Eigen::Vector3d>& target,
                          const std::vector<Eigen::Vector3d>& target_normals,
                          const IcpSettings& settings) = 0;
  /// Point-to-plane ICP on the clouds set, with the normals given.
  virtual IcpOutcome align(const Eigen::Isometry3d& initial) = 0;
  /// The peer's whole job from raw clouds: its own target normals (k neighbours), its own
  /// search structure, then the same ICP.
  virtual IcpOutcome normals_and_align(const Eigen::Isometry3d& initial) = 0;
  /// Threads the peer may use (a peer without threads ignores it).
  virtual void set_threads(int threads) = 0;
};

/// The peers built into this binary (empty when neither library was found).
std::vector<std::unique_ptr<PeerIcp>> available_peers();

/// What was looked for and not found, for the table's notes.
std::string missing_peers();

}  // namespace ulc_peers
