// Which peers this bench_peers was built with (see peer_icp.hpp and bench/CMakeLists.txt).
#include "peers/peer_icp.hpp"

namespace ulc_peers {

#ifdef ULC_BENCH_HAVE_PCL
std::unique_ptr<PeerIcp> make_pcl_peer();
#endif
#ifdef ULC_BENCH_HAVE_OPEN3D
std::unique_ptr<PeerIcp> make_open3d_peer();
#endif

std::vector<std::unique_ptr<PeerIcp>> available_peers() {
  std::vector<std::unique_ptr<PeerIcp>> peers;
#ifdef ULC_BENCH_HAVE_PCL
  peers.push_back(make_pcl_peer());
#endif
#ifdef ULC_BENCH_HAVE_OPEN3D
  peers.push_back(make_open3d_peer());
#endif
  return peers;
}

std::string missing_peers() {
  std::string missing;
#ifndef ULC_BENCH_HAVE_PCL
  missing += "PCL (libpcl-dev)";
#endif
#ifndef ULC_BENCH_HAVE_OPEN3D
  missing += std::string(missing.empty() ? "" : ", ") + "Open3D (libopen3d-dev)";
#endif
  return missing;
}

}  // namespace ulc_peers
