// The procedural town: a grid of streets with sidewalks, curbs, buildings set back from the
// street, street furniture, parked cars, and a random route that follows the streets.
//
// Conventions this header owns:
//   - Streets run along x and y through the nodes (i * pitch, j * pitch), i < nodes_x,
//     j < nodes_y. The roadway is |offset| <= road_half_width from a street's centre line;
//     sidewalks (raised kCurbHeight, tilted with the ground) run from there for
//     sidewalk_width; blocks, buildings included, start beyond. Blocks also ring the grid
//     so that the outer streets have buildings on both sides.
//   - Traffic drives on the right: the route's lane centre is lane_offset to the right of the
//     street centre line; parked cars stand at parking_offset, clear of the lane.
//   - Turns are circular arcs (right_turn_radius, left_turn_radius) chosen to keep the vehicle
//     inside the roadway; the route never U-turns and never leaves the grid.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "ulc/sim/ground.hpp"
#include "ulc/sim/path.hpp"
#include "ulc/sim/scene_parts.hpp"

namespace ulc::sim {

struct TownLayout {
  int nodes_x = 6;
  int nodes_y = 6;
  double pitch = 100.0;
  double road_half_width = 7.0;
  double sidewalk_width = 4.0;
  double lane_offset = 3.0;
  double parking_offset = 5.8;
  double right_turn_radius = 7.0;
  double left_turn_radius = 10.0;
  double relief_amplitude = 0.6;
  static constexpr double kCurbHeight = 0.15;

  double max_x() const { return (nodes_x - 1) * pitch; }
  double max_y() const { return (nodes_y - 1) * pitch; }
  Eigen::Vector2d node(int i, int j) const { return {i * pitch, j * pitch}; }
  bool has_node(int i, int j) const { return i >= 0 && j >= 0 && i < nodes_x && j < nodes_y; }
  /// Buildings and furniture start this far from a street's centre line.
  double block_margin() const { return road_half_width + sidewalk_width; }

  /// Distance from (x, y) to the nearest street centre line.
  double distance_to_street(double x, double y) const {
    auto clamp_index = [](double v, double pitch, int n) {
      return std::clamp(static_cast<int>(std::round(v / pitch)), 0, n - 1);
    };
    const double sx = clamp_index(x, pitch, nodes_x) * pitch;  // nearest street along y
    const double sy = clamp_index(y, pitch, nodes_y) * pitch;  // nearest street along x
    const double d_vertical = std::hypot(x - sx, y - std::clamp(y, 0.0, max_y()));
    const double d_horizontal = std::hypot(y - sy, x - std::clamp(x, 0.0, max_x()));
    return std::min(d_vertical, d_horizontal);
  }
};

namespace detail {

inline Eigen::Vector2d right_of(const Eigen::Vector2d& d) {
  return {d.y(), -d.x()};
}
inline Eigen::Vector2d left_of(const Eigen::Vector2d& d) {
  return {-d.y(), d.x()};
}

/// Sidewalk slab of `length` along `dir` starting at `start` (a point on the curb line), on the
/// side `side` (unit, away from the road); tilted to the local ground.
inline void add_sidewalk_slab(Scene& scene, const GroundRelief& g, const Eigen::Vector2d& start,
                              const Eigen::Vector2d& dir, const Eigen::Vector2d& side,
                              double length, double width) {
  const Eigen::Vector2d c2 = start + 0.5 * length * dir + 0.5 * width * side;
  const Eigen::Vector2d grad = g.gradient(c2.x(), c2.y());
  const Vec3d up = Vec3d(-grad.x(), -grad.y(), 1.0).normalized();
  Vec3d ax = Vec3d(dir.x(), dir.y(), 0.0);
  ax = (ax - ax.dot(up) * up).normalized();
  Mat3d axes;
  axes.col(0) = ax;
  axes.col(1) = up.cross(ax);
  axes.col(2) = up;
  const double thickness = 0.6;
  // The slab's top follows the ground's tangent plane at its centre; slabs are short (<= 5 m)
  // so the relief's curvature leaves only millimetre steps between neighbours.
  const Vec3d top_center(c2.x(), c2.y(), g.height(c2.x(), c2.y()) + TownLayout::kCurbHeight);
  scene.add(OrientedBox{top_center - 0.5 * thickness * up, axes,
                        Vec3d(0.5 * length, 0.5 * width, 0.5 * thickness), 0.35f});
}

struct Frontage {
  Eigen::Vector2d start;   ///< first corner of the building line
  Eigen::Vector2d along;   ///< unit, along the street
  Eigen::Vector2d inward;  ///< unit, into the block
  double from, to;         ///< usable range along the frontage
};

inline void add_frontage(Scene& scene, CounterRng& rng, const GroundRelief& g, const Frontage& f) {
  const double yaw = std::atan2(f.along.y(), f.along.x());
  double s = f.from + rng.uniform(0.0, 4.0);
  while (f.to - s > 8.0) {
    const double width = std::min(rng.uniform(10.0, 32.0), f.to - s);
    const double setback = rng.uniform(1.0, 5.0);
    const double depth = rng.uniform(10.0, 30.0 - setback - 0.5);
    const Eigen::Vector2d o2 = f.start + (s + 0.5 * width) * f.along + setback * f.inward;
    const double jitter = rng.chance(0.25) ? deg_to_rad(rng.uniform(-4.0, 4.0)) : 0.0;
    const Placement at =
        Placement::yawed(Vec3d(o2.x(), o2.y(), g.height(o2.x(), o2.y())), yaw + jitter);
    add_building(scene, at, BuildingSpec::random(rng, width, depth));
    s += width;
    // The gap to the next building: open, a wall or a fence along the building line.
    const double gap = rng.chance(0.3) ? 0.0 : rng.uniform(2.0, 9.0);
    if (gap > 1.5 && f.to - s > gap) {
      const Eigen::Vector2d w2 = f.start + s * f.along + rng.uniform(0.5, 2.0) * f.inward;
      const Placement line = Placement::yawed(Vec3d(w2.x(), w2.y(), g.height(w2.x(), w2.y())), yaw);
      const double pick = rng.uniform();
      if (pick < 0.35)
        add_wall(scene, line, gap, rng.uniform(1.2, 2.6), 0.3, 0.4f);
      else if (pick < 0.6)
        add_fence(scene, line, gap, rng.uniform(1.0, 1.8));
    }
    s += gap;
  }
}

/// Lamps, trees, signs and parked cars along one side of the street from node a to node b.
inline void add_street_side(Scene& scene, CounterRng& rng, const GroundRelief& g,
                            const TownLayout& town, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b, double side_sign) {
  const Eigen::Vector2d dir = (b - a).normalized();
  const Eigen::Vector2d side = side_sign * left_of(dir);
  const double length = (b - a).norm();
  const double clear = town.block_margin() + 4.0;  // keep intersections open
  auto at = [&](double s, double offset) { return Eigen::Vector2d(a + s * dir + offset * side); };
  for (double s = clear + rng.uniform(0.0, 10.0); s < length - clear;
       s += rng.uniform(25.0, 35.0)) {
    const Eigen::Vector2d p = at(s, town.road_half_width + 0.5);
    const Eigen::Vector2d back = -side;
    add_lamp_pole(scene, rng, p.x(), p.y(), g.height(p.x(), p.y()) + TownLayout::kCurbHeight,
                  std::atan2(back.y(), back.x()));
  }
  for (double s = clear + rng.uniform(0.0, 8.0); s < length - clear; s += rng.uniform(9.0, 25.0)) {
    if (rng.chance(0.25)) continue;
    const Eigen::Vector2d p = at(s, town.block_margin() - 1.3);
    add_tree(scene, rng, p.x(), p.y(), g.height(p.x(), p.y()) + TownLayout::kCurbHeight);
  }
  {  // A sign facing the traffic arriving at node b.
    const Eigen::Vector2d p = at(length - town.block_margin() - 1.0, town.road_half_width + 0.8);
    add_sign(scene, p.x(), p.y(), g.height(p.x(), p.y()) + TownLayout::kCurbHeight,
             std::atan2(-dir.y(), -dir.x()));
  }
  if (rng.chance(0.6)) {
    for (double s = clear + rng.uniform(0.0, 6.0); s < length - clear - 5.0;
         s += rng.uniform(5.5, 18.0)) {
      const Eigen::Vector2d p = at(s, town.parking_offset);
      const double yaw = std::atan2(dir.y(), dir.x()) + deg_to_rad(rng.uniform(-2.5, 2.5));
      add_car(scene, rng, Placement::yawed(Vec3d(p.x(), p.y(), g.height(p.x(), p.y())), yaw));
    }
  }
}

}  // namespace detail

/// Adds the whole town to `scene` (ground, sidewalks, blocks, furniture).
inline void add_town(Scene& scene, const TownLayout& town, const GroundRelief& relief,
                     std::uint64_t key) {
  using Eigen::Vector2d;
  CounterRng rng(hash_key(key, 0x70776eULL));
  const double m = town.block_margin();
  // Ground: asphalt on the roadway, earth and grass elsewhere.
  GroundMeshSpec mesh;
  mesh.x0 = -town.pitch - 20.0;
  mesh.y0 = -town.pitch - 20.0;
  mesh.x1 = town.max_x() + town.pitch + 20.0;
  mesh.y1 = town.max_y() + town.pitch + 20.0;
  mesh.spacing = 4.0;
  mesh.roughness = 0.01;
  mesh.key = hash_key(key, 0x67726eULL);
  scene.set_ground(GroundGrid(relief, mesh, [&](double x, double y) {
    return town.distance_to_street(x, y) <= town.road_half_width ? 0.1f : 0.28f;
  }));

  // Sidewalks: along both sides of every street segment, and the four corners of each node.
  for (int j = 0; j < town.nodes_y; ++j)
    for (int i = 0; i < town.nodes_x; ++i) {
      const Vector2d n = town.node(i, j);
      for (int q = 0; q < 4; ++q) {
        const Vector2d sx(q & 1 ? 1.0 : -1.0, 0.0), sy(0.0, q & 2 ? 1.0 : -1.0);
        const Vector2d corner = n + town.road_half_width * (sx + sy);
        detail::add_sidewalk_slab(scene, relief, corner, sx, sy, town.sidewalk_width,
                                  town.sidewalk_width);
      }
      // Where no street leaves the node (grid edge), the sidewalk runs across the end.
      for (const auto& d : {Vector2d(1, 0), Vector2d(0, 1), Vector2d(-1, 0), Vector2d(0, -1)}) {
        if (town.has_node(i + static_cast<int>(d.x()), j + static_cast<int>(d.y()))) continue;
        const Vector2d start = n + town.road_half_width * (d + detail::left_of(d));
        detail::add_sidewalk_slab(scene, relief, start, detail::right_of(d), d,
                                  2.0 * town.road_half_width, town.sidewalk_width);
      }
      for (const auto& step : {Vector2d(1, 0), Vector2d(0, 1)}) {
        const int ni = i + static_cast<int>(step.x()), nj = j + static_cast<int>(step.y());
        if (!town.has_node(ni, nj)) continue;
        const Vector2d b = town.node(ni, nj);
        const double length = (b - n).norm() - 2.0 * town.road_half_width;
        for (double side : {1.0, -1.0}) {
          const Vector2d out = side * detail::left_of(step);
          const Vector2d curb0 = n + town.road_half_width * step + town.road_half_width * out;
          const int pieces = static_cast<int>(std::ceil(length / 5.0));
          for (int k = 0; k < pieces; ++k)
            detail::add_sidewalk_slab(scene, relief, curb0 + (k * length / pieces) * step, step,
                                      out, length / pieces, town.sidewalk_width);
        }
      }
    }

  // Blocks, including a ring around the grid.
  for (int bj = -1; bj < town.nodes_y; ++bj)
    for (int bi = -1; bi < town.nodes_x; ++bi) {
      const double xa = bi * town.pitch, ya = bj * town.pitch;
      const double xb = xa + town.pitch, yb = ya + town.pitch;
      const bool inner_x = bi >= 0 && bi < town.nodes_x - 1;
      const bool inner_y = bj >= 0 && bj < town.nodes_y - 1;
      const bool south = inner_x && bj >= 0;
      const bool north = inner_x && bj + 1 < town.nodes_y;
      const bool west = inner_y && bi >= 0;
      const bool east = inner_y && bi + 1 < town.nodes_x;
      const double len = town.pitch - 2.0 * m;
      const double reserve = (south || north) ? 30.0 : 0.0;
      if (south)
        detail::add_frontage(scene, rng, relief, {{xa + m, ya + m}, {1, 0}, {0, 1}, 0, len});
      if (north)
        detail::add_frontage(scene, rng, relief, {{xb - m, yb - m}, {-1, 0}, {0, -1}, 0, len});
      if (west)
        detail::add_frontage(scene, rng, relief,
                             {{xa + m, yb - m}, {0, -1}, {1, 0}, reserve, len - reserve});
      if (east)
        detail::add_frontage(scene, rng, relief,
                             {{xb - m, ya + m}, {0, 1}, {-1, 0}, reserve, len - reserve});
      if (south || north || west || east) {  // courtyard trees
        const int trees = static_cast<int>(rng.below(4));
        for (int k = 0; k < trees; ++k) {
          const double x = rng.uniform(xa + m + 32.0, xb - m - 32.0);
          const double y = rng.uniform(ya + m + 32.0, yb - m - 32.0);
          add_tree(scene, rng, x, y, relief.height(x, y));
        }
      }
    }

  // Street furniture and parked cars on both sides of every street segment.
  for (int j = 0; j < town.nodes_y; ++j)
    for (int i = 0; i < town.nodes_x; ++i)
      for (const auto& step : {Vector2d(1, 0), Vector2d(0, 1)}) {
        const int ni = i + static_cast<int>(step.x()), nj = j + static_cast<int>(step.y());
        if (!town.has_node(ni, nj)) continue;
        for (double side : {1.0, -1.0})
          detail::add_street_side(scene, rng, relief, town, town.node(i, j), town.node(ni, nj),
                                  side);
      }
}

/// A random drive along the town's streets of at least `min_length` metres: starts mid-block,
/// turns at intersections (never U-turns, never leaves the grid), keeps to the right lane.
inline Path2d town_route(const TownLayout& town, std::uint64_t key, double min_length) {
  using Eigen::Vector2d;
  CounterRng rng(hash_key(key, 0x726f757465ULL));
  const std::array<Eigen::Vector2i, 4> dirs = {Eigen::Vector2i(1, 0), Eigen::Vector2i(0, 1),
                                               Eigen::Vector2i(-1, 0), Eigen::Vector2i(0, -1)};
  // Start on a street segment near the centre, heading east.
  Eigen::Vector2i cur(town.nodes_x / 2 - 1, town.nodes_y / 2);
  Eigen::Vector2i heading = dirs[0];
  if (!town.has_node(cur.x() + 1, cur.y())) cur = Eigen::Vector2i(0, 0);
  auto lane = [&](const Eigen::Vector2i& node, const Eigen::Vector2i& d) {
    return Vector2d(town.node(node.x(), node.y()) +
                    town.lane_offset * detail::right_of(d.cast<double>()));
  };
  const Vector2d start = lane(cur, heading) + 0.45 * town.pitch * heading.cast<double>();
  cur += heading;
  std::vector<PathCorner> corners;
  double length = 0.55 * town.pitch;
  while (length < min_length + town.pitch) {  // the last leg and fillets shorten it a little
    // Options at this node: straight, left, right (whichever streets exist).
    std::array<Eigen::Vector2i, 3> options;
    std::array<double, 3> weights;
    int n = 0;
    const Eigen::Vector2i left(-heading.y(), heading.x()), right(heading.y(), -heading.x());
    for (const auto& [d, w] :
         {std::pair{heading, 0.4}, std::pair{left, 0.3}, std::pair{right, 0.3}}) {
      if (!town.has_node(cur.x() + d.x(), cur.y() + d.y())) continue;
      options[n] = d;
      weights[n] = w;
      ++n;
    }
    double total = 0.0;
    for (int k = 0; k < n; ++k) total += weights[k];
    double pick = rng.uniform() * total;
    int choice = n - 1;
    for (int k = 0; k < n; ++k) {
      if (pick < weights[k]) {
        choice = k;
        break;
      }
      pick -= weights[k];
    }
    const Eigen::Vector2i next = options[choice];
    if (next != heading) {
      const bool is_left = next == left;
      const Vector2d corner = town.node(cur.x(), cur.y()) +
                              town.lane_offset * (detail::right_of(heading.cast<double>()) +
                                                  detail::right_of(next.cast<double>()));
      corners.push_back({corner, is_left ? town.left_turn_radius : town.right_turn_radius});
    }
    heading = next;
    cur += heading;
    length += town.pitch;
  }
  const Vector2d finish = lane(cur, heading) - 0.4 * town.pitch * heading.cast<double>();
  return fillet_polyline(start, corners, finish);
}

}  // namespace ulc::sim
