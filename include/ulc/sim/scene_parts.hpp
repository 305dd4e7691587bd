// Building blocks shared by the scene generators: boxes in a local frame, and the things that
// stand in streets (buildings with facade relief, trees, poles, cars, walls, fences).
//
// Conventions this header owns:
//   - A Placement is a local frame on the ground: x along the frontage or object, y to its
//     left, z up; boxes are given by local corners and become OrientedBoxes.
//   - Reflectivities are in [0, 1]: asphalt ~0.1, glass ~0.1, concrete/plaster 0.3..0.6,
//     paint up to 0.8. The sensor models turn them into intensities and dropout.
//   - Every object takes its randomness from the CounterRng it is handed (scene builders are
//     serial), so a seed fixes the scene.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "ulc/core/angles.hpp"
#include "ulc/sim/random.hpp"
#include "ulc/sim/scene.hpp"

namespace ulc::sim {

inline double deg_to_rad(double d) {
  return d * kPi / 180.0;
}

/// A local frame on the ground, rotated about z by `yaw` (optionally tilted).
struct Placement {
  Vec3d origin = Vec3d::Zero();
  Mat3d rotation = Mat3d::Identity();

  static Placement yawed(const Vec3d& origin, double yaw) {
    return Placement{origin, Eigen::AngleAxisd(yaw, Vec3d::UnitZ()).toRotationMatrix()};
  }
  Vec3d to_world(const Vec3d& local) const { return origin + rotation * local; }
};

/// Adds the box with local corners lo, hi.
inline void add_local_box(Scene& scene, const Placement& at, const Vec3d& lo, const Vec3d& hi,
                          float reflectivity) {
  scene.add(OrientedBox{at.to_world(0.5 * (lo + hi)), at.rotation, 0.5 * (hi - lo), reflectivity});
}

/// A building: main body with a street facade of pilasters, floor bands and optional
/// balconies in front of a recessed wall (window recesses), a roof parapet, and sometimes a
/// rear wing. Local frame: the facade faces -y and starts at y = 0; x in [-width/2, width/2];
/// z = 0 at the ground at the origin; the body reaches 1 m below ground to sit on any slope.
struct BuildingSpec {
  double width = 20.0;
  double depth = 15.0;
  int floors = 4;
  double floor_height = 3.2;
  double bay = 3.6;      ///< pilaster spacing
  double recess = 0.25;  ///< window recess depth behind the facade frame
  bool balconies = false;
  double wing_depth = 0.0;   ///< rear wing (0: none)
  double wing_height = 0.0;  ///< metres
  float wall_reflectivity = 0.2f;
  float frame_reflectivity = 0.5f;

  static BuildingSpec random(CounterRng& rng, double width, double depth) {
    BuildingSpec b;
    b.width = width;
    b.depth = depth;
    b.floors = 2 + static_cast<int>(rng.below(10));
    b.floor_height = rng.uniform(2.9, 3.6);
    b.bay = rng.uniform(3.0, 4.8);
    b.recess = rng.uniform(0.15, 0.4);
    b.balconies = rng.chance(0.4);
    if (rng.chance(0.3)) {
      b.wing_depth = rng.uniform(6.0, 12.0);
      b.wing_height = b.floor_height * static_cast<double>(1 + rng.below(3));
    }
    b.wall_reflectivity = static_cast<float>(rng.uniform(0.08, 0.3));
    b.frame_reflectivity = static_cast<float>(rng.uniform(0.3, 0.7));
    return b;
  }
};

inline void add_building(Scene& scene, const Placement& at, const BuildingSpec& b) {
  const double hw = 0.5 * b.width;
  const double height = b.floors * b.floor_height;
  const double r = b.recess;
  // Body (its front wall is the back of the window recesses) and roof parapet.
  add_local_box(scene, at, Vec3d(-hw, r, -1.0), Vec3d(hw, b.depth, height), b.wall_reflectivity);
  add_local_box(scene, at, Vec3d(-hw - 0.15, -0.15, height),
                Vec3d(hw + 0.15, b.depth, height + 0.9), b.frame_reflectivity);
  // Pilasters at bay spacing, end pilasters included.
  const int bays = std::max(1, static_cast<int>(std::round(b.width / b.bay)));
  const double bay = b.width / bays;
  for (int k = 0; k <= bays; ++k) {
    const double x = -hw + k * bay;
    const double x0 = std::max(-hw, x - 0.3), x1 = std::min(hw, x + 0.3);
    add_local_box(scene, at, Vec3d(x0, 0.0, -1.0), Vec3d(x1, r + 0.02, height),
                  b.frame_reflectivity);
  }
  // Floor bands (sills and lintels in one).
  for (int f = 1; f < b.floors; ++f) {
    const double z = f * b.floor_height;
    add_local_box(scene, at, Vec3d(-hw, 0.0, z - 0.35), Vec3d(hw, r + 0.02, z + 0.1),
                  b.frame_reflectivity);
  }
  // Balconies on every other bay above the ground floor: slab and parapet.
  if (b.balconies) {
    for (int f = 1; f < b.floors; ++f) {
      const double z = f * b.floor_height;
      for (int k = f % 2; k < bays; k += 2) {
        const double x0 = -hw + k * bay + 0.4, x1 = -hw + (k + 1) * bay - 0.4;
        add_local_box(scene, at, Vec3d(x0, -1.3, z - 0.1), Vec3d(x1, 0.0, z + 0.12),
                      b.frame_reflectivity);
        add_local_box(scene, at, Vec3d(x0, -1.3, z + 0.12), Vec3d(x1, -1.22, z + 1.05), 0.25f);
      }
    }
  }
  if (b.wing_depth > 0.0) {
    add_local_box(scene, at, Vec3d(-hw, b.depth, -1.0),
                  Vec3d(-hw + 0.45 * b.width, b.depth + b.wing_depth, b.wing_height),
                  b.frame_reflectivity);
  }
}

/// A tree: trunk cylinder and a porous canopy ellipsoid above it. `ground` is the ground height.
inline void add_tree(Scene& scene, CounterRng& rng, double x, double y, double ground) {
  const double trunk_h = rng.uniform(2.2, 4.0);
  const double trunk_r = rng.uniform(0.1, 0.25);
  scene.add(VerticalCylinder{x, y, ground - 0.5, ground + trunk_h + 0.5, trunk_r, 0.35f});
  const double rxy = rng.uniform(1.8, 3.5);
  const double rz = rng.uniform(1.5, 3.0);
  scene.add(PorousEllipsoid{Vec3d(x, y, ground + trunk_h + 0.8 * rz),
                            Vec3d(rxy * rng.uniform(0.85, 1.15), rxy * rng.uniform(0.85, 1.15), rz),
                            rng.uniform(0.6, 1.6), static_cast<float>(rng.uniform(0.25, 0.45))});
}

/// A street lamp: pole and an arm reaching over the road in direction `arm_yaw`.
inline void add_lamp_pole(Scene& scene, CounterRng& rng, double x, double y, double ground,
                          double arm_yaw) {
  const double h = rng.uniform(6.0, 8.5);
  const double r = rng.uniform(0.07, 0.12);
  scene.add(VerticalCylinder{x, y, ground - 0.5, ground + h, r, 0.45f});
  const Placement arm = Placement::yawed(Vec3d(x, y, ground + h), arm_yaw);
  add_local_box(scene, arm, Vec3d(0.0, -0.06, -0.12), Vec3d(1.8, 0.06, 0.0), 0.5f);
  add_local_box(scene, arm, Vec3d(1.4, -0.2, -0.3), Vec3d(2.2, 0.2, -0.12), 0.6f);
}

/// A traffic sign: post and a plate facing along `facing_yaw` (the plate's normal).
inline void add_sign(Scene& scene, double x, double y, double ground, double facing_yaw) {
  scene.add(VerticalCylinder{x, y, ground - 0.5, ground + 2.8, 0.04, 0.5f});
  const Placement plate = Placement::yawed(Vec3d(x, y, ground + 2.4), facing_yaw);
  add_local_box(scene, plate, Vec3d(-0.03, -0.35, -0.35), Vec3d(0.03, 0.35, 0.35), 0.9f);
}

/// A parked car: body and cabin, x along its length. `at` is on the ground at its centre.
inline void add_car(Scene& scene, CounterRng& rng, const Placement& at) {
  const double l = rng.uniform(3.9, 4.9), w = rng.uniform(1.7, 1.9);
  const auto paint = static_cast<float>(rng.uniform(0.15, 0.8));
  add_local_box(scene, at, Vec3d(-l / 2, -w / 2, 0.25), Vec3d(l / 2, w / 2, 0.95), paint);
  const double cl = l * rng.uniform(0.45, 0.6);
  const double back = -l / 2 + rng.uniform(0.5, 0.9);
  add_local_box(scene, at, Vec3d(back, -w / 2 + 0.08, 0.95),
                Vec3d(back + cl, w / 2 - 0.08, rng.uniform(1.35, 1.6)), 0.12f);
}

/// A wall of given length, height and thickness along local x from x = 0.
inline void add_wall(Scene& scene, const Placement& at, double length, double height,
                     double thickness, float reflectivity) {
  add_local_box(scene, at, Vec3d(0.0, -thickness / 2, -0.5), Vec3d(length, thickness / 2, height),
                reflectivity);
}

/// A fence: posts every ~2.5 m and two rails, along local x from x = 0.
inline void add_fence(Scene& scene, const Placement& at, double length, double height) {
  const int posts = std::max(2, static_cast<int>(length / 2.5) + 1);
  for (int k = 0; k < posts; ++k) {
    const Vec3d p = at.to_world(Vec3d(length * k / (posts - 1), 0.0, 0.0));
    scene.add(VerticalCylinder{p.x(), p.y(), p.z() - 0.3, p.z() + height, 0.04, 0.5f});
  }
  for (double z : {0.35 * height, 0.9 * height})
    add_local_box(scene, at, Vec3d(0.0, -0.03, z - 0.05), Vec3d(length, 0.03, z + 0.05), 0.5f);
}

}  // namespace ulc::sim
