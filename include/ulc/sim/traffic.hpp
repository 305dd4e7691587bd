// Moving traffic: cars driving against the ego vehicle in the opposite lane of its route.
// They occlude, and they return points that do not belong to the static world, as real
// traffic does; registration has to cope with both.
//
// Conventions this header owns:
//   - The opposite lane is the route shifted 2 * lane_offset to the left, driven backwards:
//     a car's arc length along it is s(t) = s0 - speed * t. Cars ride on the analytic ground.
//   - A car is two boxes (body and cabin) in its own frame (x forward, origin on the ground
//     at its centre), like the parked cars of scene_parts.hpp.
//   - Within one LiDAR frame a car moves on a straight line between its poses at the frame's
//     start and end, keeping its mid-frame orientation (over 0.1 s the difference to its curved
//     path is millimetres); every ray sees it at the ray's own instant.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "ulc/core/angles.hpp"
#include "ulc/sim/ground.hpp"
#include "ulc/sim/path.hpp"
#include "ulc/sim/primitives.hpp"
#include "ulc/sim/random.hpp"

namespace ulc::sim {

/// A box moving linearly during one frame: centre c0 + u (c1 - c0) at frame fraction u.
struct MovingBox {
  OrientedBox box;                 ///< at the frame start
  Vec3d velocity = Vec3d::Zero();  ///< metres per second
  double radius_sq = 0.0;          ///< bounding sphere, for cheap rejection
};

struct TrafficCar {
  double s0 = 0.0;     ///< arc length along the opposite lane at t = 0
  double speed = 8.0;  ///< m/s
  double length = 4.4, width = 1.8, cabin_height = 1.5;
  float paint = 0.5f;
};

class Traffic {
 public:
  Traffic() = default;

  /// `count` cars spread along the opposite lane of `route`, speeds in [5, 11] m/s.
  Traffic(const Path2d& route, double lane_offset, const GroundRelief& ground, int count,
          std::uint64_t key)
      : ground_(ground) {
    if (count <= 0 || route.empty()) return;
    lane_ = offset_path(route, 2.0 * lane_offset);
    CounterRng rng(hash_key(key, 0x747266ULL));
    const double spacing = lane_.length() / count;
    for (int i = 0; i < count; ++i) {
      TrafficCar car;
      car.s0 = (i + rng.uniform(0.2, 0.8)) * spacing;
      car.speed = rng.uniform(5.0, 11.0);
      car.length = rng.uniform(3.9, 4.9);
      car.width = rng.uniform(1.7, 1.9);
      car.cabin_height = rng.uniform(1.35, 1.6);
      car.paint = static_cast<float>(rng.uniform(0.15, 0.8));
      cars_.push_back(car);
    }
  }

  bool empty() const { return cars_.empty(); }
  const std::vector<TrafficCar>& cars() const { return cars_; }

  /// Body and cabin boxes of the cars within `radius` of `center` during [t0, t1].
  void frame_boxes(double t0, double t1, const Vec3d& center, double radius,
                   std::vector<MovingBox>& out) const {
    out.clear();
    for (const TrafficCar& car : cars_) {
      const double sa = car.s0 - car.speed * t0, sb = car.s0 - car.speed * t1;
      if (sb < 0.0 || sa > lane_.length()) continue;  // not on the road yet / any more
      const PathPoint pa = lane_.at(sa), pb = lane_.at(sb), pm = lane_.at(0.5 * (sa + sb));
      const Vec3d ca(pa.position.x(), pa.position.y(),
                     ground_.height(pa.position.x(), pa.position.y()));
      if ((ca - center).norm() > radius) continue;
      const Vec3d cb(pb.position.x(), pb.position.y(),
                     ground_.height(pb.position.x(), pb.position.y()));
      // Driving backwards along the lane: the car faces against the lane's heading.
      const Mat3d R = Eigen::AngleAxisd(pm.heading + kPi, Vec3d::UnitZ()).toRotationMatrix();
      const Vec3d velocity = (cb - ca) / (t1 - t0);
      const double l = car.length, w = car.width;
      add(out, ca + R * Vec3d(0.0, 0.0, 0.6), R, Vec3d(l / 2, w / 2, 0.35), car.paint, velocity);
      const double cabin = 0.5 * (car.cabin_height - 0.95);
      add(out, ca + R * Vec3d(-0.05 * l, 0.0, 0.95 + cabin), R,
          Vec3d(0.27 * l, w / 2 - 0.08, cabin), 0.12f, velocity);
    }
  }

 private:
  static void add(std::vector<MovingBox>& out, const Vec3d& c, const Mat3d& R, const Vec3d& half,
                  float refl, const Vec3d& velocity) {
    MovingBox m;
    m.box = OrientedBox{c, R, half, refl};
    m.velocity = velocity;
    m.radius_sq = half.squaredNorm();
    out.push_back(m);
  }

  Path2d lane_;
  GroundRelief ground_;
  std::vector<TrafficCar> cars_;
};

}  // namespace ulc::sim
