// A world: the built scene, the ground the vehicle rides on, and the lane route it drives.
//
// Conventions this header owns:
//   - SceneKind names the three environments: town (the realistic one), highway and tunnel
//     (the deliberately degenerate ones).
//   - build_world is deterministic in its arguments: route_length is how far the vehicle may
//     drive (the route is at least that long; degenerate scenes are sized to it);
//     traffic_per_km oncoming cars per kilometre of route (traffic.hpp), 0 for none.
#pragma once

#include <cstdint>
#include <string>

#include "ulc/sim/degenerate_scenes.hpp"
#include "ulc/sim/ground.hpp"
#include "ulc/sim/path.hpp"
#include "ulc/sim/scene.hpp"
#include "ulc/sim/town.hpp"
#include "ulc/sim/traffic.hpp"

namespace ulc::sim {

enum class SceneKind { town, highway, tunnel };

inline const char* to_string(SceneKind k) {
  switch (k) {
    case SceneKind::town:
      return "town";
    case SceneKind::highway:
      return "highway";
    default:
      return "tunnel";
  }
}

struct World {
  SceneKind kind = SceneKind::town;
  Scene scene;
  GroundRelief ground;  ///< the surface the vehicle's wheels follow
  Path2d route;         ///< lane centre line the vehicle drives along
  Traffic traffic;      ///< oncoming cars on the route's opposite lane
  TownLayout town;      ///< meaningful for SceneKind::town
  TunnelLayout tunnel;  ///< meaningful for SceneKind::tunnel
  HighwayLayout highway;
};

inline World build_world(SceneKind kind, std::uint64_t seed, double route_length,
                         double traffic_per_km = 0.0) {
  World w;
  w.kind = kind;
  const std::uint64_t key = hash_key(seed, 0x776f726c64ULL);
  switch (kind) {
    case SceneKind::town:
      w.ground = GroundRelief::random(hash_key(key, 1), w.town.relief_amplitude);
      add_town(w.scene, w.town, w.ground, hash_key(key, 2));
      w.route = town_route(w.town, hash_key(key, 3), route_length);
      break;
    case SceneKind::highway: {
      const Path2d center = highway_centerline(w.highway, hash_key(key, 4), route_length);
      add_highway(w.scene, w.highway, center);
      w.route = offset_path(center, w.highway.lane_offset());
      break;
    }
    case SceneKind::tunnel: {
      const double length = std::max(route_length, 300.0) + 60.0;
      w.tunnel.start_x = 25.0;
      w.tunnel.end_x = length - 35.0;
      add_tunnel(w.scene, w.tunnel);
      w.route = Path2d(Eigen::Vector2d(0.0, w.tunnel.lane_offset), 0.0);
      w.route.add_line(length);
      break;
    }
  }
  w.scene.build();
  const double lane = kind == SceneKind::town      ? w.town.lane_offset
                      : kind == SceneKind::highway ? -w.highway.lane_offset()
                                                   : -w.tunnel.lane_offset;
  const int cars = static_cast<int>(std::round(traffic_per_km * w.route.length() / 1000.0));
  w.traffic = Traffic(w.route, lane, w.ground, cars, hash_key(key, 5));
  return w;
}

}  // namespace ulc::sim
