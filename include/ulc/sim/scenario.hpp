// Rigs and named scenarios: which LiDARs sit where on the vehicle, their clocks, the pairs to
// calibrate, the environment and the driving style.
//
// Conventions this header owns:
//   - T_vehicle_lidar maps LiDAR-frame points into the vehicle frame (vehicle.hpp). For a pair,
//     T_base_target = T_vehicle_base^-1 T_vehicle_target (p_base = T_base_target p_target).
//   - Clocks: each LiDAR's clock reads t_own = t_true - clock_offset_s (t_true is the
//     trajectory's time). A pair's offset in the docs/design.md convention
//     t_base_clock = t_target_clock + time_offset_s is therefore
//     time_offset_s = clock_offset(target) - clock_offset(base).
//   - The first LiDAR of a scenario is the base of its default pairs; pair scenarios are
//     named "<base>-<target>" after the paper (64 = HDL-64E, 32 = VLP-32C, 16 = VLP-16).
//   - The COLORFUL rig (the paper's simulated dataset) carries all seven paper sensors; the
//     two-LiDAR paper scenarios use the same mounts, so their ground truths agree.
//   - Default frame rate 10 Hz; colorful runs at 20 Hz as in the paper.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"
#include "ulc/sim/sensor_catalog.hpp"
#include "ulc/sim/trajectory.hpp"
#include "ulc/sim/vehicle.hpp"
#include "ulc/sim/world.hpp"

namespace ulc::sim {

struct LidarMount {
  std::string name;   ///< folder name in the dataset
  std::string model;  ///< a sensor_model_names() entry
  Isometry3d T_vehicle_lidar = Isometry3d::Identity();
  double rate_hz = 10.0;
  double clock_offset_s = 0.0;  ///< t_own = t_true - clock_offset_s
};

struct LidarPair {
  std::string base;
  std::string target;
};

struct ScenarioSpec {
  std::string name;
  std::string description;
  SceneKind scene = SceneKind::town;
  MotionSpec motion;
  double traffic_per_km = 12.0;  ///< oncoming cars per km of route (0: an empty road)
  std::vector<LidarMount> lidars;
  std::vector<LidarPair> pairs;

  const LidarMount* find(const std::string& lidar) const {
    for (const LidarMount& m : lidars)
      if (m.name == lidar) return &m;
    return nullptr;
  }
};

/// Ground truth of one pair, derived from the mounts.
struct PairTruth {
  std::string base;
  std::string target;
  Isometry3d T_base_target = Isometry3d::Identity();
  double time_offset_s = 0.0;  ///< t_base_clock = t_target_clock + time_offset_s
};

struct ScenarioCheck {
  bool ok = true;
  std::string reason;
};

/// A mount at (x, y, z) metres with roll, pitch, yaw in degrees (R = Rz Ry Rx).
inline Isometry3d mount_pose(double x, double y, double z, double roll_deg, double pitch_deg,
                             double yaw_deg) {
  Isometry3d T = Isometry3d::Identity();
  T.linear() = rotation_from_rpy(deg_to_rad(roll_deg), deg_to_rad(pitch_deg), deg_to_rad(yaw_deg));
  T.translation() = Vec3d(x, y, z);
  return T;
}

inline std::vector<PairTruth> pair_truths(const ScenarioSpec& spec) {
  std::vector<PairTruth> out;
  for (const LidarPair& p : spec.pairs) {
    const LidarMount* b = spec.find(p.base);
    const LidarMount* t = spec.find(p.target);
    if (!b || !t) continue;
    PairTruth truth;
    truth.base = p.base;
    truth.target = p.target;
    truth.T_base_target = b->T_vehicle_lidar.inverse() * t->T_vehicle_lidar;
    truth.time_offset_s = t->clock_offset_s - b->clock_offset_s;
    out.push_back(truth);
  }
  return out;
}

/// Sets one LiDAR's clock offset (t_own = t_true - offset); false for an unknown name.
inline bool set_clock_offset(ScenarioSpec& spec, const std::string& lidar, double offset_s) {
  for (LidarMount& m : spec.lidars)
    if (m.name == lidar) {
      m.clock_offset_s = offset_s;
      return true;
    }
  return false;
}

/// Sets every LiDAR's frame rate.
inline void set_rate(ScenarioSpec& spec, double rate_hz) {
  for (LidarMount& m : spec.lidars) m.rate_hz = rate_hz;
}

/// Structural checks: known models, unique names, valid pairs and rates, mounts outside the
/// vehicle body.
inline ScenarioCheck check_scenario(const ScenarioSpec& spec) {
  ScenarioCheck c;
  auto fail = [&](std::string why) {
    c.ok = false;
    c.reason = std::move(why);
    return c;
  };
  if (spec.lidars.empty()) return fail("scenario has no LiDAR");
  const VehicleBody body = VehicleBody::car();
  for (std::size_t i = 0; i < spec.lidars.size(); ++i) {
    const LidarMount& m = spec.lidars[i];
    if (m.name.empty()) return fail("a LiDAR has an empty name");
    if (!sensor_model(m.model)) return fail("unknown sensor model '" + m.model + "'");
    if (!(m.rate_hz >= 1.0 && m.rate_hz <= 100.0))
      return fail("rate of '" + m.name + "' not in 1..100 Hz");
    if (!std::isfinite(m.clock_offset_s))
      return fail("clock offset of '" + m.name + "' not finite");
    if (body.contains(m.T_vehicle_lidar.translation()))
      return fail("LiDAR '" + m.name + "' is mounted inside the vehicle body");
    for (std::size_t j = 0; j < i; ++j)
      if (spec.lidars[j].name == m.name) return fail("duplicate LiDAR name '" + m.name + "'");
  }
  for (const LidarPair& p : spec.pairs)
    if (!spec.find(p.base) || !spec.find(p.target) || p.base == p.target)
      return fail("pair " + p.base + " -> " + p.target + " names unknown or equal LiDARs");
  return c;
}

namespace detail {

// The COLORFUL rig: mounts of the seven paper sensors (vehicle frame, metres and degrees).
inline LidarMount colorful_mount(const std::string& name) {
  if (name == "lidar64") return {name, "HDL-64E", mount_pose(1.30, 0.00, 2.00, 0.4, -0.6, 1.2)};
  if (name == "lidar32") return {name, "VLP-32C", mount_pose(0.35, 0.55, 1.78, 2.0, -3.0, 38.0)};
  if (name == "lidar16") return {name, "VLP-16", mount_pose(0.35, -0.55, 1.76, -1.5, 2.5, -52.0)};
  if (name == "horizon") return {name, "Horizon", mount_pose(2.40, 0.50, 1.70, 0.5, 4.0, 12.0)};
  if (name == "mid40") return {name, "Mid-40", mount_pose(2.45, -0.45, 1.70, 1.0, 6.0, -15.0)};
  if (name == "avia") return {name, "Avia", mount_pose(2.85, 0.00, 1.35, 0.0, -3.0, 2.0)};
  return {"tele", "Tele-15", mount_pose(2.60, -0.05, 1.80, -0.5, 1.5, 0.8)};
}

inline ScenarioSpec pair_scenario(const std::string& name, const std::string& base,
                                  const std::string& target, const std::string& what) {
  ScenarioSpec s;
  s.name = name;
  s.description = what;
  s.lidars = {colorful_mount(base), colorful_mount(target)};
  s.pairs = {{base, target}};
  return s;
}

inline ScenarioSpec with_pairs_from_first(ScenarioSpec s) {
  s.pairs.clear();
  for (std::size_t i = 1; i < s.lidars.size(); ++i)
    s.pairs.push_back({s.lidars[0].name, s.lidars[i].name});
  return s;
}

}  // namespace detail

inline std::vector<std::string> scenario_names() {
  return {"64-32",      "32-16",       "horizon-tele", "64-horizon",  "32-avia",
          "64-tele",    "16-tele",     "32-mid40",     "colorful",    "ring-5x16",
          "pitched-90", "side-bpearl", "upside-down",  "offset-50ms", "highway",
          "tunnel",     "campus-ss",   "campus-bs",    "tiers",       "flicar-lift"};
}

/// The named scenario, or nothing for an unknown name (see scenario_names()).
inline std::optional<ScenarioSpec> scenario(const std::string& name) {
  using detail::colorful_mount;
  using detail::pair_scenario;
  const std::string town = "town drive; ";
  if (name == "64-32")
    return pair_scenario(name, "lidar64", "lidar32", town + "HDL-64E base, VLP-32C target");
  if (name == "32-16")
    return pair_scenario(name, "lidar32", "lidar16", town + "VLP-32C base, VLP-16 target");
  if (name == "horizon-tele")
    return pair_scenario(name, "horizon", "tele", town + "Livox Horizon base, Tele-15 target");
  if (name == "64-horizon")
    return pair_scenario(name, "lidar64", "horizon", town + "HDL-64E base, Horizon target");
  if (name == "32-avia")
    return pair_scenario(name, "lidar32", "avia", town + "VLP-32C base, Avia target");
  if (name == "64-tele")
    return pair_scenario(name, "lidar64", "tele", town + "HDL-64E base, Tele-15 target");
  if (name == "16-tele")
    return pair_scenario(name, "lidar16", "tele", town + "VLP-16 base, Tele-15 target");
  if (name == "32-mid40")
    return pair_scenario(name, "lidar32", "mid40", town + "VLP-32C base, Mid-40 target");
  if (name == "colorful") {
    ScenarioSpec s;
    s.name = name;
    s.description = town + "the paper's COLORFUL rig: 3 spinning + 4 Livox LiDARs at 20 Hz";
    for (const char* n : {"lidar64", "lidar32", "lidar16", "horizon", "mid40", "avia", "tele"})
      s.lidars.push_back(colorful_mount(n));
    set_rate(s, 20.0);
    s.pairs = {{"lidar64", "lidar32"}, {"lidar32", "lidar16"}, {"horizon", "tele"},
               {"lidar64", "horizon"}, {"lidar32", "avia"},    {"lidar64", "tele"},
               {"lidar16", "tele"},    {"lidar32", "mid40"}};
    return s;
  }
  if (name == "ring-5x16") {
    ScenarioSpec s;
    s.name = name;
    s.description =
        town + "five VLP-16: roof centre (base) and four corners yawed outwards, tilted down";
    s.lidars = {{"roof", "VLP-16", mount_pose(1.30, 0.00, 1.75, 0.0, 0.0, 0.0)},
                {"front_left", "VLP-16", mount_pose(3.85, 0.90, 0.80, -3.0, 8.0, 45.0)},
                {"front_right", "VLP-16", mount_pose(3.85, -0.90, 0.80, 3.0, 8.0, -45.0)},
                {"rear_left", "VLP-16", mount_pose(-1.05, 0.90, 0.90, -3.0, 8.0, 135.0)},
                {"rear_right", "VLP-16", mount_pose(-1.05, -0.90, 0.90, 3.0, 8.0, -135.0)}};
    return detail::with_pairs_from_first(s);
  }
  if (name == "pitched-90") {
    ScenarioSpec s;
    s.name = name;
    s.description =
        town + "VLP-32C base; VLP-16 pitched 90 deg (spin axis forward): little overlap";
    s.lidars = {{"base32", "VLP-32C", mount_pose(1.30, 0.00, 1.80, 0.0, 0.0, 0.0)},
                {"pitched16", "VLP-16", mount_pose(2.55, 0.30, 1.72, 3.0, 90.0, 0.0)}};
    return detail::with_pairs_from_first(s);
  }
  if (name == "side-bpearl") {
    ScenarioSpec s;
    s.name = name;
    s.description =
        town + "RS-Helios base on the roof; RS-Bpearl on the left flank looking sideways";
    s.lidars = {{"helios", "RS-Helios", mount_pose(1.30, 0.00, 1.80, 0.0, 0.0, 0.5)},
                {"bpearl_left", "RS-Bpearl", mount_pose(1.50, 1.02, 1.10, -90.0, 0.0, 4.0)}};
    return detail::with_pairs_from_first(s);
  }
  if (name == "upside-down") {
    ScenarioSpec s;
    s.name = name;
    s.description = town + "VLP-32C base; HDL-32E hanging upside down in front of the windscreen";
    s.lidars = {{"base32", "VLP-32C", mount_pose(1.30, 0.00, 1.80, 0.0, 0.0, 0.0)},
                {"hanging32e", "HDL-32E", mount_pose(3.00, 0.30, 1.30, 180.0, 2.0, 20.0)}};
    return detail::with_pairs_from_first(s);
  }
  if (name == "offset-50ms") {
    ScenarioSpec s = pair_scenario(name, "lidar64", "lidar32",
                                   town + "64-32 rig; the VLP-32C's clock runs 50 ms behind");
    set_clock_offset(s, "lidar32", 0.05);
    return s;
  }
  if (name == "highway" || name == "tunnel") {
    ScenarioSpec s = pair_scenario(
        name, "lidar64", "lidar32",
        name == "highway" ? "open highway with guard rails (degenerate along the road); 64-32 rig"
                          : "long straight tunnel (degenerate along its axis); 64-32 rig");
    s.scene = name == "highway" ? SceneKind::highway : SceneKind::tunnel;
    s.motion.min_speed = 8.0;
    s.motion.slowdowns_per_km = 0.0;
    s.motion.bumps = false;
    s.traffic_per_km = 0.0;  // nothing may break the degeneracy
    return s;
  }
  if (name == "campus-ss") {
    ScenarioSpec s;
    s.name = name;
    s.description = town + "solid-state rig: RS-M1 (base), Avia, RS-Helios";
    s.lidars = {{"rs_m1", "RS-M1", mount_pose(2.90, 0.00, 1.40, 0.0, 3.0, 0.0)},
                {"avia", "Avia", mount_pose(2.40, 0.60, 1.70, 0.0, 5.0, 10.0)},
                {"helios", "RS-Helios", mount_pose(1.20, 0.00, 1.85, 0.0, 0.0, -1.0)}};
    return detail::with_pairs_from_first(s);
  }
  if (name == "campus-bs") {
    ScenarioSpec s;
    s.name = name;
    s.description = town + "blind-spot rig: two RS-Helios and two side RS-Bpearl";
    s.lidars = {{"helios_front", "RS-Helios", mount_pose(2.00, 0.00, 1.80, 0.0, 1.0, 0.0)},
                {"helios_rear", "RS-Helios", mount_pose(0.40, 0.00, 1.85, 0.0, -1.0, 180.0)},
                {"bpearl_left", "RS-Bpearl", mount_pose(1.50, 1.02, 1.10, -90.0, 0.0, 4.0)},
                {"bpearl_right", "RS-Bpearl", mount_pose(1.50, -1.02, 1.10, 90.0, 0.0, -3.0)}};
    return detail::with_pairs_from_first(s);
  }
  if (name == "tiers") {
    ScenarioSpec s;
    s.name = name;
    s.description = town + "TIERS-like rig: OS1-64 (base), VLP-16, OS0-128, Horizon, Avia";
    s.lidars = {{"os1", "OS1-64", mount_pose(1.30, 0.00, 1.80, 0.0, 0.0, 0.0)},
                {"vlp16", "VLP-16", mount_pose(1.00, 0.45, 1.95, 0.0, 0.0, 90.0)},
                {"os0", "OS0-128", mount_pose(0.50, 0.00, 1.75, 0.0, 0.0, 180.0)},
                {"horizon", "Horizon", mount_pose(2.30, 0.35, 1.70, 0.0, 2.0, 3.0)},
                {"avia", "Avia", mount_pose(2.30, -0.35, 1.70, 0.0, 4.0, -3.0)}};
    s = detail::with_pairs_from_first(s);
    s.pairs.push_back({"horizon", "avia"});
    return s;
  }
  if (name == "flicar-lift") {
    ScenarioSpec s;
    s.name = name;
    s.description = town + "bucket-truck platform rising and falling 4 m: OS0-128 (base), two " +
                    "LiDARs pitched 90 deg, Avia";
    s.lidars = {{"os0", "OS0-128", mount_pose(1.30, 0.00, 1.80, 0.0, 0.0, 0.0)},
                {"vlp32c_vertical", "VLP-32C", mount_pose(2.60, 0.40, 1.75, 0.0, 90.0, 0.0)},
                {"hdl32_vertical", "HDL-32E", mount_pose(2.60, -0.40, 1.75, 0.0, -90.0, 0.0)},
                {"avia", "Avia", mount_pose(2.85, 0.00, 1.35, 0.0, 2.0, -6.0)}};
    s.motion.max_speed = 6.0;
    s.motion.lift_amplitude = 4.0;
    s.motion.lift_period = 25.0;
    return detail::with_pairs_from_first(s);
  }
  return std::nullopt;
}

}  // namespace ulc::sim
