// Ray casting one LiDAR frame: every ray fired at its own instant from the sensor's pose at
// that instant, intersected with the scene, then degraded like a real measurement.
//
// Conventions this header owns:
//   - Points come out in the LiDAR's own frame at the instant each was measured (motion
//     distortion included, as a real sensor delivers them), in firing order, with times in
//     seconds since the frame's first firing and an intensity in [0, 255].
//   - Per ray: angular jitter perturbs the true direction while the reported direction stays
//     nominal; range noise is Gaussian then quantised; rays that meet the vehicle body or
//     another sensor's housing first are lost; a return survives with probability
//       (1 - base_dropout) * (1 - (r / r_eff)^3) * (1 - (1 - cos i)^4),
//     r_eff = max_range * min(1, sqrt(reflectivity / reference_reflectivity)), i the
//     incidence angle, so dropout grows with range, grazing incidence and dark surfaces.
//   - Moving traffic (traffic.hpp) is seen at each ray's own instant.
//   - Randomness per ray from hash_key(frame key, ray index): 1 and N threads, same bits.
//     TBB parallel_for over fixed-size blocks of rays; each ray writes its own slot, then a
//     serial pass compacts the hits in ray order. No allocation per ray.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "ulc/core/point_cloud.hpp"
#include "ulc/sim/scene.hpp"
#include "ulc/sim/sensor_model.hpp"
#include "ulc/sim/traffic.hpp"
#include "ulc/sim/trajectory.hpp"

namespace ulc::sim {

/// A sensor as mounted on the vehicle, with what blocks its view, ready to cast.
struct MountedSensor {
  SensorModel model;
  Isometry3d T_vehicle_lidar = Isometry3d::Identity();
  /// Vehicle body parts and other sensors' housings, in this LiDAR's frame.
  std::vector<OrientedBox> occluders;
};

/// Reused per-frame storage (one per concurrently rendered frame).
struct FrameScratch {
  PoseTable poses;                ///< T_world_vehicle over the frame's time span
  std::vector<MovingBox> movers;  ///< traffic near the vehicle during the frame
  std::vector<Eigen::Vector3f> points;
  std::vector<float> intensity;
  std::vector<double> time;
  std::vector<std::uint8_t> valid;
};

namespace detail {

struct OccluderSphere {
  Vec3d center;
  double radius_sq;
};

/// Distance along a LiDAR-frame ray to the first occluder (infinity if none).
inline double occluder_distance(const std::vector<OrientedBox>& occluders,
                                const std::vector<OccluderSphere>& spheres, const Vec3d& origin,
                                const Vec3d& dir, double t_max) {
  Ray ray;
  ray.origin = origin;
  ray.dir = dir;
  double best = t_max;
  for (std::size_t k = 0; k < occluders.size(); ++k) {
    // Cheap rejection by the bounding sphere: behind the ray or passing wide of it.
    const Vec3d c = spheres[k].center - origin;
    const double along = c.dot(dir);
    const double miss_sq = c.squaredNorm() - along * along;
    if (miss_sq > spheres[k].radius_sq || (along < 0.0 && c.squaredNorm() > spheres[k].radius_sq))
      continue;
    SurfaceHit hit;
    if (occluders[k].intersect(ray, best, hit)) best = hit.t;
  }
  return best;
}

/// Nearest moving box along the ray at frame time `dt` (lowers ray.t_max when found).
inline bool moving_hit(const std::vector<MovingBox>& movers, double dt, Ray& ray, SurfaceHit& hit) {
  bool found = false;
  for (const MovingBox& m : movers) {
    OrientedBox b = m.box;
    b.center += m.velocity * dt;
    const Vec3d c = b.center - ray.origin;
    const double along = c.dot(ray.dir);
    if (c.squaredNorm() - along * along > m.radius_sq || along < -std::sqrt(m.radius_sq)) continue;
    if (b.intersect(ray, ray.t_max, hit)) {
      ray.t_max = hit.t;
      found = true;
    }
  }
  return found;
}

template <class Pattern>
void cast_rays(const Scene& scene, const PoseTable& poses, const MountedSensor& sensor,
               const Pattern& pattern, const FrameSetup& setup, std::uint64_t frame_key,
               std::size_t grain, FrameScratch& out) {
  const std::vector<MovingBox>& movers = out.movers;
  const RangeModel& rm = sensor.model.range;
  const Mat3d R_vl = sensor.T_vehicle_lidar.linear();
  const Vec3d t_vl = sensor.T_vehicle_lidar.translation();
  std::vector<OccluderSphere> spheres;
  for (const OrientedBox& b : sensor.occluders) spheres.push_back({b.center, b.half.squaredNorm()});

  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, setup.rays, grain),
      [&](const tbb::blocked_range<std::size_t>& block) {
        for (std::size_t i = block.begin(); i != block.end(); ++i) {
          out.valid[i] = 0;
          const SensorRay sr = pattern.ray(i, setup);
          CounterRng rng(hash_key(frame_key, i));
          const double j1 = rng.approx_normal(), j2 = rng.approx_normal();
          // The true direction is the nominal one turned by the jitter angles (to first order;
          // they are ~1e-3 rad, so the second-order error is ~1e-6 rad): d/daz = (-y, x, 0),
          // d/del = (-z x / c, -z y / c, c) with c = cos(elevation).
          const Vec3d& d_nominal = sr.dir;
          const double ce = std::max(
              std::sqrt(d_nominal.x() * d_nominal.x() + d_nominal.y() * d_nominal.y()), 1e-9);
          const double ja = rm.angular_jitter * j1, je = rm.angular_jitter * j2;
          const double k = -je * d_nominal.z() / ce;
          const Vec3d d_true =
              Vec3d(d_nominal.x() - ja * d_nominal.y() + k * d_nominal.x(),
                    d_nominal.y() + ja * d_nominal.x() + k * d_nominal.y(), d_nominal.z() + je * ce)
                  .normalized();
          const double t_ego =
              occluder_distance(sensor.occluders, spheres, sr.origin, d_true, rm.max_range);
          Mat3d R_wv;
          Vec3d p_wv;
          poses.at(setup.start_time + sr.time, R_wv, p_wv);
          Ray ray;
          ray.origin = R_wv * (R_vl * sr.origin + t_vl) + p_wv;
          ray.dir = R_wv * (R_vl * d_true);
          ray.t_max = t_ego;
          ray.key = hash_key(frame_key, i, 0x776f726c64ULL);
          SurfaceHit hit, mover;
          const bool moving = !movers.empty() && moving_hit(movers, sr.time, ray, mover);
          if (!scene.intersect(ray, hit)) {
            if (!moving) continue;
            hit = mover;
          }
          if (hit.t < rm.min_range) continue;
          const double cos_inc = std::min(1.0, std::abs(hit.normal.dot(ray.dir)));
          const double r_eff =
              rm.max_range * std::min(1.0, std::sqrt(static_cast<double>(hit.reflectivity) /
                                                     rm.reference_reflectivity));
          if (hit.t >= r_eff) continue;
          const double u = hit.t / r_eff;
          const double g = 1.0 - cos_inc;
          const double keep = (1.0 - rm.base_dropout) * (1.0 - u * u * u) * (1.0 - g * g * g * g);
          if (rng.uniform() >= keep) continue;
          double n1, n2;
          rng.normal_pair(n1, n2);
          double range = hit.t + rm.range_sigma * n1;
          if (rm.range_resolution > 0.0)
            range = std::round(range / rm.range_resolution) * rm.range_resolution;
          if (range < rm.min_range) continue;
          const Vec3d p = sr.origin + range * d_nominal;
          out.points[i] = p.cast<float>();
          const double level =
              255.0 * hit.reflectivity * (0.35 + 0.65 * cos_inc) * (1.0 + 0.05 * n2);
          out.intensity[i] = static_cast<float>(std::clamp(level, 0.0, 255.0));
          out.time[i] = sr.time;
          out.valid[i] = 1;
        }
      },
      tbb::simple_partitioner());
}

}  // namespace detail

/// Casts one frame whose first firing is at `start_time` (true time) into `cloud`.
/// `frame_key` seeds every random draw of the frame; scratch.movers holds the traffic boxes
/// of the frame (at its start) and is left as given.
inline void cast_frame(const Scene& scene, const VehicleTrajectory& trajectory,
                       const MountedSensor& sensor, double rate_hz, double start_time,
                       std::uint64_t frame_key, unsigned decimation, std::size_t grain,
                       FrameScratch& scratch, PointCloud<float>& cloud) {
  const FrameSetup setup = sensor.model.setup(rate_hz, start_time, frame_key, decimation);
  scratch.poses.rebuild(trajectory, start_time, start_time + 1.0 / rate_hz);
  scratch.points.resize(setup.rays);
  scratch.intensity.resize(setup.rays);
  scratch.time.resize(setup.rays);
  scratch.valid.resize(setup.rays);
  std::visit(
      [&](const auto& pattern) {
        detail::cast_rays(scene, scratch.poses, sensor, pattern, setup, frame_key, grain, scratch);
      },
      sensor.model.pattern);
  std::size_t n = 0;
  for (std::uint8_t v : scratch.valid) n += v;
  cloud.clear();
  cloud.points.resize(n);
  cloud.intensities.resize(n);
  cloud.times.resize(n);
  std::size_t k = 0;
  for (std::size_t i = 0; i < setup.rays; ++i) {
    if (!scratch.valid[i]) continue;
    cloud.points[k] = scratch.points[i];
    cloud.intensities[k] = scratch.intensity[i];
    cloud.times[k] = scratch.time[i];
    ++k;
  }
}

}  // namespace ulc::sim
