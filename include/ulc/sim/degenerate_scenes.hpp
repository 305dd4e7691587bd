// The two deliberately degenerate scenes: an open highway and a long straight tunnel.
//
// Conventions this header owns:
//   - Both are built along their route so that nothing within sensor range varies along the
//     direction of travel: flat ground, continuous guard rails and median barrier (no posts),
//     tunnel walls of constant cross-section without lamps or niches. Registration along the
//     travel direction is then unconstrained, which is the point of these scenes.
//   - Highway: straight-ish (long straights joined by 1500 m radius bends of a few degrees),
//     dual carriageway; the route keeps to the right lane. Tunnel: along +x, entered shortly
//     after the start and left shortly before the end of the route.
#pragma once

#include <algorithm>
#include <cmath>

#include "ulc/sim/ground.hpp"
#include "ulc/sim/path.hpp"
#include "ulc/sim/scene_parts.hpp"

namespace ulc::sim {

struct HighwayLayout {
  double lane_width = 3.75;
  double median_half_width = 0.5;
  double shoulder = 2.5;
  double bend_radius = 1500.0;
  double lane_offset() const { return -(median_half_width + 1.5 * lane_width); }  ///< outer lane
  double rail_offset() const { return median_half_width + 2.0 * lane_width + shoulder; }
};

/// The highway's centre line (median), at least `min_length` metres long.
inline Path2d highway_centerline(const HighwayLayout& h, std::uint64_t key, double min_length) {
  CounterRng rng(hash_key(key, 0x687779ULL));
  Path2d path(Eigen::Vector2d(-50.0, 0.0), 0.0);
  double sign = rng.chance(0.5) ? 1.0 : -1.0;
  while (path.length() < min_length + 100.0) {
    path.add_line(rng.uniform(150.0, 400.0));
    path.add_arc(h.bend_radius, sign * deg_to_rad(rng.uniform(2.0, 6.0)));
    sign = -sign;
  }
  return path;
}

inline void add_highway(Scene& scene, const HighwayLayout& h, const Path2d& center) {
  const double length = center.length();
  GroundMeshSpec mesh;  // flat: a coarse grid only to vary the material
  mesh.x0 = -150.0;
  mesh.x1 = center.end().position.x() + 250.0;
  mesh.y0 = -400.0;
  mesh.y1 = 400.0;
  mesh.spacing = 25.0;
  mesh.roughness = 0.0;
  scene.set_ground(GroundGrid(GroundRelief(), mesh, [](double, double) { return 0.12f; }));
  // Rails and the median barrier as short tangent boxes along the curve (chord error < 1 cm).
  const double piece = 8.0;
  for (double s = 0.0; s < length; s += piece) {
    const PathPoint p = center.at(s + 0.5 * piece);
    const Eigen::Vector2d n(-std::sin(p.heading), std::cos(p.heading));
    for (double side : {1.0, -1.0}) {
      const Eigen::Vector2d c = p.position + side * h.rail_offset() * n;
      const Placement at = Placement::yawed(Vec3d(c.x(), c.y(), 0.0), p.heading);
      add_local_box(scene, at, Vec3d(-0.5 * piece - 0.05, -0.06, 0.45),
                    Vec3d(0.5 * piece + 0.05, 0.06, 0.8), 0.55f);
    }
    const Placement mid = Placement::yawed(Vec3d(p.position.x(), p.position.y(), 0.0), p.heading);
    add_local_box(scene, mid, Vec3d(-0.5 * piece - 0.05, -0.3, -0.2),
                  Vec3d(0.5 * piece + 0.05, 0.3, 0.9), 0.4f);
  }
}

struct TunnelLayout {
  double start_x = 25.0;
  double end_x = 500.0;
  double half_width = 6.0;  ///< wall to wall / 2
  double wall_height = 4.5;
  double chamfer = 1.5;
  double lane_offset = -2.5;
};

inline void add_tunnel(Scene& scene, const TunnelLayout& t) {
  const double x0 = t.start_x, x1 = t.end_x, len = x1 - x0;
  const double w = t.half_width, top = t.wall_height + t.chamfer;
  GroundMeshSpec mesh;
  mesh.x0 = -200.0;
  mesh.x1 = x1 + 250.0;
  mesh.y0 = -200.0;
  mesh.y1 = 200.0;
  mesh.spacing = 25.0;
  mesh.roughness = 0.0;
  scene.set_ground(GroundGrid(GroundRelief(), mesh, [](double, double) { return 0.12f; }));
  const Placement axis = Placement::yawed(Vec3d(x0, 0.0, 0.0), 0.0);
  for (double side : {1.0, -1.0}) {
    // Walkway, wall, and the 45 degree chamfer up to the ceiling.
    const double s = side;
    add_local_box(scene, axis, Vec3d(0.0, std::min(s * (w - 1.0), s * w), -0.2),
                  Vec3d(len, std::max(s * (w - 1.0), s * w), 0.3), 0.3f);
    add_local_box(scene, axis, Vec3d(0.0, std::min(s * w, s * (w + 0.6)), -0.5),
                  Vec3d(len, std::max(s * w, s * (w + 0.6)), t.wall_height + 0.3), 0.35f);
    const Vec3d out = Vec3d(0.0, s, 1.0).normalized();
    const Vec3d along_face = Vec3d(0.0, -s, 1.0).normalized();
    Mat3d axes;
    axes.col(0) = Vec3d::UnitX();
    axes.col(1) = along_face;
    axes.col(2) = axes.col(0).cross(axes.col(1));
    const double thickness = 0.5;
    const Vec3d face_mid(x0 + 0.5 * len, s * (w - 0.5 * t.chamfer),
                         t.wall_height + 0.5 * t.chamfer);
    scene.add(OrientedBox{face_mid + 0.5 * thickness * out, axes,
                          Vec3d(0.5 * len, 0.5 * t.chamfer * std::sqrt(2.0) + 0.2, 0.5 * thickness),
                          0.35f});
  }
  add_local_box(scene, axis, Vec3d(0.0, -(w - t.chamfer) - 0.2, top),
                Vec3d(len, w - t.chamfer + 0.2, top + 0.6), 0.35f);
  // Portals: a retaining wall around each opening, facing along the axis.
  for (double xp : {x0, x1}) {
    const double d = xp == x0 ? -1.0 : 0.0;
    add_local_box(scene, Placement(), Vec3d(xp + d, w, -0.5), Vec3d(xp + d + 1.0, 40.0, 14.0),
                  0.4f);
    add_local_box(scene, Placement(), Vec3d(xp + d, -40.0, -0.5), Vec3d(xp + d + 1.0, -w, 14.0),
                  0.4f);
    add_local_box(scene, Placement(), Vec3d(xp + d, -w, top), Vec3d(xp + d + 1.0, w, 14.0), 0.4f);
  }
}

}  // namespace ulc::sim
