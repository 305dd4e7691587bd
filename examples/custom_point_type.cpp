// Your own point type, used by ULC in place: no copy into a ULC type.
//
// Two ways to plug in:
//  1. A std::vector of a struct with x, y, z members works out of the box; members named
//     `time` (or `t`), `intensity` and `normal_x/y/z` are picked up automatically.
//  2. Any other container: specialise ulc::CloudTraits for it (below: a driver's scan message
//     whose per-point time is an integer in nanoseconds).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "ulc/core/cloud.hpp"
#include "ulc/core/kdtree.hpp"
#include "ulc/core/normals.hpp"
#include "ulc/core/voxel_downsample.hpp"

// ---- 1. A vehicle stack's point struct -----------------------------------------------------
struct VehiclePoint {
  float x, y, z;
  float intensity;
  std::uint16_t ring;  // not used by ULC; ignored
  double time;         // seconds since the frame timestamp
};

// ---- 2. A driver's message with its own layout ---------------------------------------------
struct DriverScan {
  double stamp = 0;                      // frame start, seconds
  std::vector<float> xyz;                // x0 y0 z0 x1 y1 z1 ...
  std::vector<std::uint32_t> offset_ns;  // per-point time since stamp, nanoseconds
};

namespace ulc {
template <>
struct CloudTraits<DriverScan> {
  using Scalar = float;
  static std::size_t size(const DriverScan& s) { return s.xyz.size() / 3; }
  static Eigen::Vector3f point(const DriverScan& s, std::size_t i) {
    return {s.xyz[3 * i], s.xyz[3 * i + 1], s.xyz[3 * i + 2]};
  }
  static double time(const DriverScan& s, std::size_t i) { return s.offset_ns[i] * 1e-9; }
};
}  // namespace ulc

// A generic function, as every ULC algorithm is: it reads any cloud through the traits.
template <typename Cloud>
void describe(const char* name, const Cloud& cloud) {
  const std::size_t n = ulc::traits::size(cloud);
  double t_max = 0;
  for (std::size_t i = 0; i < n; ++i) t_max = std::max(t_max, ulc::traits::time(cloud, i));
  std::printf("%-14s %6zu points, per-point time: %s (sweep %.3f s)\n", name, n,
              ulc::traits::has_time(cloud) ? "yes" : "no", t_max);
}

int main() {
  // A synthetic sweep: 8 rings on the floor (1.5 m below the sensor), 8 on a round wall.
  std::vector<VehiclePoint> points;
  DriverScan scan;
  for (int ring = 0; ring < 16; ++ring) {
    const bool floor = ring < 8;
    const double radius = floor ? 2.0 + 0.25 * ring : 6.0;
    const double z = floor ? -1.5 : 0.25 * (ring - 8);
    for (int col = 0; col < 720; ++col) {
      const double az = col * M_PI / 360.0;
      const double t = col / 7200.0;  // a 0.1 s sweep
      const float x = static_cast<float>(radius * std::cos(az));
      const float y = static_cast<float>(radius * std::sin(az));
      points.push_back({x, y, static_cast<float>(z), 10.0f, static_cast<std::uint16_t>(ring), t});
      scan.xyz.insert(scan.xyz.end(), {x, y, static_cast<float>(z)});
      scan.offset_ns.push_back(static_cast<std::uint32_t>(t * 1e9));
    }
  }
  describe("VehiclePoint", points);
  describe("DriverScan", scan);

  // Library algorithms take the user's types directly.
  const ulc::KdTree<std::vector<VehiclePoint>> tree(points);
  const auto normals = ulc::estimate_normals(points, tree);
  const auto down = ulc::voxel_downsample(scan, 0.5);
  if (!normals.ok() || !down.ok()) {
    std::fprintf(stderr, "example failed: %s%s\n", normals.reason, down.reason);
    return 1;
  }
  std::size_t floor_normals = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i].ring < 8 && normals.points[i].valid &&
        std::abs(normals.points[i].normal.z()) > 0.99f)
      ++floor_normals;
  std::printf("normals: %zu valid, %zu floor points with a vertical normal\n", normals.valid_count,
              floor_normals);
  std::printf("voxel downsample (0.5 m) of DriverScan: %zu -> %zu points\n",
              ulc::traits::size(scan), down.cloud.size());
  return 0;
}
