// Running a scenario: the world, the drive, every LiDAR's frames and the ground truth.
//
// Conventions this header owns:
//   - Time: the trajectory runs from t = 0 (true time); recording starts at
//     kRecordingStart = 1 s, so that own-clock timestamps stay positive for clock offsets up to
//     1 s. LiDAR i fires its first frame at kRecordingStart plus a random trigger phase in
//     [0, 1/rate), then every 1/rate; it records floor(seconds * rate) frames. A frame's timestamp
//     is its first firing in the LiDAR's own clock: t_own = t_true - clock_offset_s (scenario.hpp).
//     Point times are relative to it.
//   - Frames are produced in order of their start time (ties: LiDAR order) and handed to the
//     optional FrameSink as they are made, so a writer can stream them to disk; with
//     keep_frames = false the Dataset holds only timestamps and ground truth (bounded memory).
//   - Every random draw derives from options.seed (random.hpp): the same seed gives the same
//     dataset, bit for bit, with any number of threads.
//   - Nothing here throws, prints or exits; failures come back as a status and a reason. A
//     FrameSink may stop the run by returning false (status aborted).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ulc/core/point_cloud.hpp"
#include "ulc/sim/raycast.hpp"
#include "ulc/sim/scenario.hpp"
#include "ulc/sim/trajectory.hpp"
#include "ulc/sim/vehicle.hpp"
#include "ulc/sim/world.hpp"

namespace ulc::sim {

/// True time at which recording starts (the vehicle is already moving).
constexpr double kRecordingStart = 1.0;

struct SimulationOptions {
  double seconds = 20.0;          ///< recorded duration
  std::uint64_t seed = 1;         ///< scene, route, trigger phases, noise: everything
  std::optional<double> rate_hz;  ///< overrides every LiDAR's frame rate
  /// Clock offset (t_own = t_true - offset) given to every LiDAR but the first, so that each
  /// default pair has time_offset_s = this value.
  std::optional<double> target_clock_offset_s;
  /// Parks the vehicle at its pose of this time for the whole run (no motion distortion).
  std::optional<double> static_at_s;
  unsigned decimation = 1;          ///< keep every n-th column / sample (fast tests)
  bool keep_frames = true;          ///< hold the frames in the Dataset
  double trajectory_rate_hz = 100;  ///< rate of the sampled vehicle trajectory
  std::size_t grain = 1024;         ///< rays per TBB task (fixed: results never depend on it)
};

enum class SimStatus { ok, invalid_options, invalid_scenario, aborted };

inline const char* to_string(SimStatus s) {
  switch (s) {
    case SimStatus::ok:
      return "ok";
    case SimStatus::invalid_options:
      return "invalid_options";
    case SimStatus::invalid_scenario:
      return "invalid_scenario";
    default:
      return "aborted";
  }
}

/// Outcome of Simulator::init.
struct SimCheck {
  SimStatus status = SimStatus::ok;
  std::string reason;
  bool ok() const { return status == SimStatus::ok; }
};

struct LidarRecording {
  std::string name;
  std::string model;
  Isometry3d T_vehicle_lidar = Isometry3d::Identity();
  double rate_hz = 10.0;
  double clock_offset_s = 0.0;
  std::vector<double> timestamps;         ///< frame starts, own clock
  std::vector<PointCloud<float>> frames;  ///< empty unless keep_frames
  std::size_t points = 0;                 ///< total over all frames
};

struct TrajectorySample {
  double t = 0.0;  ///< true time (the clock of LiDARs with zero clock offset)
  Vec3d position = Vec3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< R_world_vehicle
};

struct Dataset {
  std::string scenario;
  std::uint64_t seed = 0;
  double seconds = 0.0;
  std::vector<LidarRecording> lidars;
  std::vector<PairTruth> pairs;
  std::vector<TrajectorySample> trajectory;

  const LidarRecording* find(const std::string& name) const {
    for (const LidarRecording& l : lidars)
      if (l.name == name) return &l;
    return nullptr;
  }
};

/// Handed to a FrameSink for every frame, in production order.
struct FrameEvent {
  std::size_t lidar;  ///< index in Dataset::lidars
  std::size_t frame;
  double timestamp;  ///< own clock
  const PointCloud<float>& cloud;
};
using FrameSink = std::function<bool(const FrameEvent&)>;  ///< false stops the run
using ProgressFn = std::function<void(std::size_t frames_done, std::size_t frames_total)>;

struct SimulationResult {
  SimStatus status = SimStatus::ok;
  std::string reason;
  Dataset dataset;
  bool ok() const { return status == SimStatus::ok; }
};

/// The prepared simulation: world, trajectory and mounted sensors. Frames can be rendered in
/// any order, each independently (render_frame is not reentrant: it reuses one scratch).
class Simulator {
 public:
  /// Builds everything; returns !ok with a reason for bad options or scenarios.
  SimCheck init(const ScenarioSpec& spec_in, const SimulationOptions& options) {
    options_ = options;
    spec_ = spec_in;
    if (!(options.seconds > 0.0) || !std::isfinite(options.seconds) || options.seconds > 3600.0)
      return fail("seconds must be in (0, 3600]");
    if (options.decimation < 1) return fail("decimation must be >= 1");
    if (options.grain < 1) return fail("grain must be >= 1");
    if (!(options.trajectory_rate_hz > 0.0)) return fail("trajectory_rate_hz must be > 0");
    if (options.rate_hz) set_rate(spec_, *options.rate_hz);
    if (options.target_clock_offset_s)
      for (std::size_t i = 1; i < spec_.lidars.size(); ++i)
        spec_.lidars[i].clock_offset_s = *options.target_clock_offset_s;
    const ScenarioCheck check = check_scenario(spec_);
    if (!check.ok) return SimCheck{SimStatus::invalid_scenario, check.reason};
    for (std::size_t i = 0; i < spec_.lidars.size(); ++i)
      if (frame_count(i) == 0)
        return fail("seconds must cover at least one frame of '" + spec_.lidars[i].name + "'");

    const MotionSpec& motion = spec_.motion;
    horizon_ = kRecordingStart + options.seconds + 2.0 / min_rate() + 0.1;
    if (options.static_at_s) {
      if (!(*options.static_at_s >= 0.0) || *options.static_at_s > 3600.0)
        return fail("static_at_s must be in [0, 3600]");
      horizon_ = std::max(horizon_, *options.static_at_s + 0.1);  // the parking spot is driven to
    }
    const double route_length = motion.max_speed * (horizon_ + 2.0) + 50.0;
    if (!(spec_.traffic_per_km >= 0.0 && spec_.traffic_per_km <= 200.0))
      return SimCheck{SimStatus::invalid_scenario, "traffic_per_km must be in [0, 200]"};
    world_ = build_world(spec_.scene, options.seed, route_length, spec_.traffic_per_km);
    trajectory_ = VehicleTrajectory(world_.route, world_.ground, motion,
                                    hash_key(options.seed, 0x647269ULL), horizon_);
    if (options.static_at_s) trajectory_.freeze_at(*options.static_at_s);
    mount_sensors();
    return SimCheck{};
  }

  const ScenarioSpec& spec() const { return spec_; }
  const SimulationOptions& options() const { return options_; }
  const World& world() const { return world_; }
  const VehicleTrajectory& trajectory() const { return trajectory_; }
  std::size_t lidar_count() const { return sensors_.size(); }
  const MountedSensor& sensor(std::size_t lidar) const { return sensors_[lidar]; }

  std::size_t frame_count(std::size_t lidar) const {
    return static_cast<std::size_t>(
        std::floor(options_.seconds * spec_.lidars[lidar].rate_hz + 1e-9));
  }
  /// True time of the first firing of frame k.
  double frame_start(std::size_t lidar, std::size_t k) const {
    return kRecordingStart + trigger_[lidar] + static_cast<double>(k) / spec_.lidars[lidar].rate_hz;
  }
  /// Frame k's timestamp in the LiDAR's own clock.
  double frame_timestamp(std::size_t lidar, std::size_t k) const {
    return frame_start(lidar, k) - spec_.lidars[lidar].clock_offset_s;
  }
  /// T_world_lidar at true time t (the exact trajectory, not the ray caster's table).
  Isometry3d T_world_lidar(std::size_t lidar, double t_true) const {
    return trajectory_.pose(t_true) * spec_.lidars[lidar].T_vehicle_lidar;
  }

  void render_frame(std::size_t lidar, std::size_t k, PointCloud<float>& cloud) {
    const std::uint64_t key = hash_key(options_.seed, lidar, k, 0x6672616d65ULL);
    const double t0 = frame_start(lidar, k), t1 = t0 + 1.0 / spec_.lidars[lidar].rate_hz;
    world_.traffic.frame_boxes(t0, t1, trajectory_.pose(t0).translation(),
                               sensors_[lidar].model.range.max_range + 20.0, scratch_.movers);
    cast_frame(world_.scene, trajectory_, sensors_[lidar], spec_.lidars[lidar].rate_hz,
               frame_start(lidar, k), key, options_.decimation, options_.grain, scratch_, cloud);
  }

  /// The Dataset without frames: mounts, timestamps, pairs and the sampled trajectory.
  Dataset metadata() const {
    Dataset d;
    d.scenario = spec_.name;
    d.seed = options_.seed;
    d.seconds = options_.seconds;
    for (std::size_t i = 0; i < spec_.lidars.size(); ++i) {
      const LidarMount& m = spec_.lidars[i];
      LidarRecording r;
      r.name = m.name;
      r.model = m.model;
      r.T_vehicle_lidar = m.T_vehicle_lidar;
      r.rate_hz = m.rate_hz;
      r.clock_offset_s = m.clock_offset_s;
      for (std::size_t k = 0; k < frame_count(i); ++k)
        r.timestamps.push_back(frame_timestamp(i, k));
      d.lidars.push_back(std::move(r));
    }
    d.pairs = pair_truths(spec_);
    const auto samples =
        static_cast<std::size_t>(std::floor(horizon_ * options_.trajectory_rate_hz));
    for (std::size_t k = 0; k <= samples; ++k) {
      const double t = static_cast<double>(k) / options_.trajectory_rate_hz;
      const Isometry3d T = trajectory_.pose(t);
      d.trajectory.push_back({t, T.translation(), Eigen::Quaterniond(T.linear()).normalized()});
    }
    return d;
  }

  /// (lidar, frame) in production order: by start time, ties by LiDAR index.
  std::vector<std::pair<std::size_t, std::size_t>> schedule() const {
    std::vector<std::pair<std::size_t, std::size_t>> order;
    for (std::size_t i = 0; i < sensors_.size(); ++i)
      for (std::size_t k = 0; k < frame_count(i); ++k) order.emplace_back(i, k);
    std::stable_sort(order.begin(), order.end(), [&](const auto& a, const auto& b) {
      return frame_start(a.first, a.second) < frame_start(b.first, b.second);
    });
    return order;
  }

 private:
  static SimCheck fail(std::string why) {
    return SimCheck{SimStatus::invalid_options, std::move(why)};
  }

  double min_rate() const {
    double r = 1e9;
    for (const LidarMount& m : spec_.lidars) r = std::min(r, m.rate_hz);
    return r;
  }

  void mount_sensors() {
    const VehicleBody body = VehicleBody::car();
    sensors_.clear();
    trigger_.clear();
    for (std::size_t i = 0; i < spec_.lidars.size(); ++i) {
      const LidarMount& m = spec_.lidars[i];
      MountedSensor s;
      s.model = *sensor_model(m.model);
      if (auto* risley = std::get_if<RisleyLidar>(&s.model.pattern))
        risley->set_session(hash_key(options_.seed, i, 0x73657373ULL));
      s.T_vehicle_lidar = m.T_vehicle_lidar;
      const Isometry3d T_lidar_vehicle = m.T_vehicle_lidar.inverse();
      for (const OrientedBox& part : body.parts)
        s.occluders.push_back(transformed(part, T_lidar_vehicle));
      for (std::size_t j = 0; j < spec_.lidars.size(); ++j) {
        if (j == i) continue;
        const OrientedBox housing{Vec3d::Zero(), Mat3d::Identity(),
                                  sensor_model(spec_.lidars[j].model)->housing_half, 0.5f};
        s.occluders.push_back(
            transformed(housing, T_lidar_vehicle * spec_.lidars[j].T_vehicle_lidar));
      }
      sensors_.push_back(std::move(s));
      trigger_.push_back(unit_double(hash_key(options_.seed, i, 0x74726967ULL)) / m.rate_hz);
    }
  }

  static OrientedBox transformed(const OrientedBox& b, const Isometry3d& T) {
    return OrientedBox{T * b.center, T.linear() * b.axes, b.half, b.reflectivity};
  }

  ScenarioSpec spec_;
  SimulationOptions options_;
  World world_;
  VehicleTrajectory trajectory_;
  std::vector<MountedSensor> sensors_;
  std::vector<double> trigger_;
  double horizon_ = 0.0;
  FrameScratch scratch_;
};

/// Initialises `sim`; on failure writes the status into `result`, else its metadata.
inline bool start_simulation(Simulator& sim, const ScenarioSpec& spec,
                             const SimulationOptions& options, SimulationResult& result) {
  const SimCheck check = sim.init(spec, options);
  if (!check.ok()) {
    result.status = check.status;
    result.reason = check.reason;
    return false;
  }
  result.dataset = sim.metadata();
  return true;
}

/// Runs the scenario. Frames go to `sink` as they are made (if given) and into the Dataset
/// when options.keep_frames; `progress` hears about every frame.
inline SimulationResult simulate(const ScenarioSpec& spec, const SimulationOptions& options,
                                 const FrameSink& sink = {}, const ProgressFn& progress = {}) {
  SimulationResult result;
  Simulator sim;
  if (!start_simulation(sim, spec, options, result)) return result;
  const auto order = sim.schedule();
  PointCloud<float> cloud;
  for (std::size_t n = 0; n < order.size(); ++n) {
    const auto [lidar, k] = order[n];
    sim.render_frame(lidar, k, cloud);
    LidarRecording& rec = result.dataset.lidars[lidar];
    rec.points += cloud.size();
    if (sink && !sink(FrameEvent{lidar, k, rec.timestamps[k], cloud})) {
      result.status = SimStatus::aborted;
      result.reason = "stopped by the frame sink";
      return result;
    }
    if (options.keep_frames) {
      if (rec.frames.size() <= k) rec.frames.resize(k + 1);
      rec.frames[k] = cloud;
    }
    if (progress) progress(n + 1, order.size());
  }
  return result;
}

}  // namespace ulc::sim
