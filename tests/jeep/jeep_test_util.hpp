// Helpers of the JEEP tests and of bench_jeep: simulated rig drives (in memory, or cached on
// disk for the benchmarks), ground-truth poses, the paper's disturbance, statistics.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "../support/test_units.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/types.hpp"
#include "ulc/sim/simulate.hpp"

namespace jeep_test {

using ulc::Isometry3d;
using ulc::Vec3d;
using ulc::Vec6d;

using ulc_test::kDeg;

struct DriveSpec {
  std::string scenario = "64-32";
  double seconds = 1.0;
  std::uint64_t seed = 1;
  unsigned decimation = 1;
  double start_s = 0.0;  ///< frames before this (true time) are not kept
};

/// Simulates the drive, keeping the frames (in memory) that start at or after start_s.
inline ulc::sim::Dataset simulate(const DriveSpec& d) {
  ulc::sim::SimulationOptions o;
  o.seconds = d.seconds;
  o.seed = d.seed;
  o.decimation = d.decimation;
  ulc::sim::Simulator sim;
  const auto spec = ulc::sim::scenario(d.scenario);
  if (!spec || !sim.init(*spec, o).ok()) return {};
  ulc::sim::Dataset out = sim.metadata();
  for (std::size_t l = 0; l < out.lidars.size(); ++l) {
    auto& rec = out.lidars[l];
    std::vector<double> kept;
    for (std::size_t k = 0; k < rec.timestamps.size(); ++k) {
      if (sim.frame_start(l, k) < d.start_s) continue;
      rec.frames.emplace_back();
      sim.render_frame(l, k, rec.frames.back());
      kept.push_back(rec.timestamps[k]);
    }
    rec.timestamps = kept;
  }
  return out;
}

/// 0.1 s of the 64-32 rig parked (the vehicle stands still from the start), every second
/// point: single frames that need no deskewing.
inline ulc::sim::Dataset parked_64_32() {
  ulc::sim::SimulationOptions o;
  o.seconds = 0.1;
  o.seed = 4;
  o.decimation = 2;
  o.static_at_s = 5.0;
  return ulc::sim::simulate(*ulc::sim::scenario("64-32"), o).dataset;
}

namespace detail {

template <typename T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
bool get(std::istream& in, T& v) {
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&v), sizeof(T)));
}
template <typename T>
void put_array(std::ostream& out, const T* data, std::size_t n) {
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(n * sizeof(T)));
}
template <typename T>
bool get_array(std::istream& in, T* data, std::size_t n) {
  return static_cast<bool>(
      in.read(reinterpret_cast<char*>(data), static_cast<std::streamsize>(n * sizeof(T))));
}

}  // namespace detail

/// simulate(d), with the frames cached under `dir` (written on first use, read afterwards).
/// Per frame: timestamp, point count, then x y z (float32) per point, per-point times (double).
inline ulc::sim::Dataset cached(const DriveSpec& d,
                                const std::filesystem::path& dir = "/tmp/ulc_jeep_cache") {
  std::ostringstream name;
  name << d.scenario << "_s" << d.seed << "_" << d.seconds << "s_d" << d.decimation << "_from"
       << d.start_s << ".v2.bin";
  const auto path = dir / name.str();
  ulc::sim::SimulationOptions o;
  o.seconds = d.seconds;
  o.seed = d.seed;
  o.decimation = d.decimation;
  ulc::sim::Simulator sim;
  const auto spec = ulc::sim::scenario(d.scenario);
  if (!spec || !sim.init(*spec, o).ok()) return {};
  ulc::sim::Dataset meta = sim.metadata();
  std::ifstream in(path, std::ios::binary);
  if (in) {
    bool good = true;
    for (auto& rec : meta.lidars) {
      std::uint64_t frames = 0;
      good = good && detail::get(in, frames);
      rec.frames.resize(good ? frames : 0);
      std::vector<double> stamps(rec.frames.size());
      for (std::size_t k = 0; good && k < rec.frames.size(); ++k) {
        std::uint64_t n = 0;
        good = good && detail::get(in, stamps[k]) && detail::get(in, n);
        auto& f = rec.frames[k];
        std::vector<float> xyz(good ? 3 * n : 0);
        f.times.resize(good ? n : 0);
        good = good && detail::get_array(in, xyz.data(), xyz.size()) &&
               detail::get_array(in, f.times.data(), f.times.size());
        f.points.resize(f.times.size());
        for (std::size_t i = 0; good && i < n; ++i)
          f.points[i] = Eigen::Vector3f(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
      }
      rec.timestamps = stamps;
    }
    if (good) return meta;
  }
  ulc::sim::Dataset data = simulate(d);
  std::filesystem::create_directories(dir);
  const auto tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    for (auto& rec : data.lidars) {
      detail::put(out, static_cast<std::uint64_t>(rec.frames.size()));
      for (std::size_t k = 0; k < rec.frames.size(); ++k) {
        auto& f = rec.frames[k];
        detail::put(out, rec.timestamps[k]);
        detail::put(out, static_cast<std::uint64_t>(f.size()));
        std::vector<float> xyz;
        xyz.reserve(3 * f.size());
        for (const auto& p : f.points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
        detail::put_array(out, xyz.data(), xyz.size());
        detail::put_array(out, f.times.data(), f.times.size());
        f.intensities.clear();  // not cached: keep the two paths alike
      }
    }
  }
  std::filesystem::rename(tmp, path);
  return data;
}

/// T_world_vehicle at true time t, interpolated between the trajectory samples.
inline Isometry3d vehicle_pose(const ulc::sim::Dataset& d, double t) {
  const auto& traj = d.trajectory;
  const double dt = traj[1].t - traj[0].t;
  const double u = std::clamp((t - traj[0].t) / dt, 0.0, static_cast<double>(traj.size() - 2));
  const auto k = static_cast<std::size_t>(std::floor(u));
  auto iso = [](const ulc::sim::TrajectorySample& s) {
    Isometry3d T = Isometry3d::Identity();
    T.linear() = s.orientation.toRotationMatrix();
    T.translation() = s.position;
    return T;
  };
  return ulc::interpolate(iso(traj[k]), iso(traj[k + 1]), u - static_cast<double>(k));
}

/// T_world_lidar at a timestamp of that LiDAR's own clock.
inline Isometry3d lidar_pose(const ulc::sim::Dataset& d, std::size_t lidar, double t_own) {
  const auto& rec = d.lidars[lidar];
  return vehicle_pose(d, t_own + rec.clock_offset_s) * rec.T_vehicle_lidar;
}

/// The paper's disturbance of a ground truth: a rotation of `angle` about a random axis and a
/// translation of `distance` in a random direction, C = C_gt * delta.
inline Isometry3d disturbed(const Isometry3d& truth, std::mt19937_64& rng, double angle_rad,
                            double distance_m) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Vec3d axis = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  const Vec3d dir = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  Isometry3d out = truth;
  out.linear() = truth.linear() * ulc::so3_exp(Vec3d(angle_rad * axis));
  out.translation() = truth.translation() + distance_m * dir;
  return out;
}

inline double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

}  // namespace jeep_test
