// The ego vehicle's body: the solid parts that block the sensors' own rays.
//
// Conventions this header owns:
//   - Vehicle frame (as in trajectory.hpp): x forward, y left, z up, origin on the ground
//     below the rear axle. A car of 4.7 x 1.9 m: lower body from 0.25 to 1.05 m, cabin up to
//     1.55 m, a roof rack plate up to 1.62 m. Sensors are mounted outside these parts.
//   - A ray that reaches the body (or another sensor's housing) before the scene is lost, as
//     real drivers lose or filter self-returns.
#pragma once

#include <vector>

#include "ulc/sim/primitives.hpp"

namespace ulc::sim {

struct VehicleBody {
  std::vector<OrientedBox> parts;  ///< vehicle frame

  static VehicleBody car() {
    VehicleBody b;
    auto box = [&](Vec3d lo, Vec3d hi) {
      b.parts.push_back(OrientedBox{0.5 * (lo + hi), Mat3d::Identity(), 0.5 * (hi - lo), 0.5f});
    };
    box(Vec3d(-0.95, -0.95, 0.25), Vec3d(3.75, 0.95, 1.05));  // lower body
    box(Vec3d(0.10, -0.85, 1.05), Vec3d(2.70, 0.85, 1.55));   // cabin
    box(Vec3d(0.20, -0.70, 1.55), Vec3d(2.20, 0.70, 1.62));   // roof rack plate
    return b;
  }

  /// True when the point (vehicle frame) is inside a body part (mount sanity checks).
  bool contains(const Vec3d& p) const {
    for (const OrientedBox& part : parts) {
      const Vec3d local = part.axes.transpose() * (p - part.center);
      if ((local.cwiseAbs().array() <= part.half.array()).all()) return true;
    }
    return false;
  }
};

}  // namespace ulc::sim
