// Helpers of the HOTS tests: random poses and synthetic planar scenes seen by a moving sensor.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "../support/test_units.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/types.hpp"

namespace hots_test {

using ulc::Isometry3d;
using ulc::Vec3d;
using ulc::Vec6d;

using ulc_test::kDeg;

/// [rho; phi] with Gaussian entries of the given standard deviations.
inline Vec6d random_vector6(std::mt19937_64& rng, double sigma_t, double sigma_r) {
  std::normal_distribution<double> g(0.0, 1.0);
  Vec6d xi;
  for (int i = 0; i < 3; ++i) xi[i] = sigma_t * g(rng);
  for (int i = 3; i < 6; ++i) xi[i] = sigma_r * g(rng);
  return xi;
}

/// A rotation of up to `angle` about a random axis and a translation of up to `distance`.
inline Isometry3d random_pose(std::mt19937_64& rng, double angle, double distance) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Vec3d axis = Vec3d(u(rng), u(rng), u(rng)).normalized();
  Isometry3d T = Isometry3d::Identity();
  T.linear() = ulc::so3_exp(Vec3d(angle * u(rng) * axis));
  T.translation() = distance * Vec3d(u(rng), u(rng), u(rng));
  return T;
}

/// A box-shaped room with a few inner walls and pillars: planes in every direction, so a
/// window of frames is fully constrained. The room is shifted off the integer grid: a surface
/// lying exactly on a voxel boundary splits its noise between two cells by sign, and cells
/// extracted at a wrong pose then keep a truncated, biased share of each frame's noise.
struct Room {
  Vec3d offset = Vec3d(0.37, 0.61, 0.43);

  /// Points on the surfaces within `range` of `centre`, about `spacing` apart, with noise.
  std::vector<Vec3d> sample(const Vec3d& centre, double range, double spacing, double noise,
                            std::mt19937_64& rng) const {
    std::normal_distribution<double> g(0.0, noise);
    std::uniform_real_distribution<double> jitter(-0.5, 0.5);
    std::vector<Vec3d> out;
    auto plane = [&](const Vec3d& origin, const Vec3d& e1, const Vec3d& e2, double l1, double l2) {
      const Vec3d n = e1.cross(e2).normalized();
      for (double a = 0; a < l1; a += spacing) {
        for (double b = 0; b < l2; b += spacing) {
          const Vec3d p =
              origin + (a + spacing * jitter(rng)) * e1 + (b + spacing * jitter(rng)) * e2;
          if ((offset + p - centre).norm() > range) continue;
          out.push_back(offset + p + g(rng) * n);
        }
      }
    };
    const Vec3d X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
    plane(Vec3d(-20, -12, 0), X, Y, 40, 24);  // floor
    plane(Vec3d(-20, -12, 0), X, Z, 40, 6);   // walls
    plane(Vec3d(-20, 12, 0), X, Z, 40, 6);
    plane(Vec3d(-20, -12, 0), Y, Z, 24, 6);
    plane(Vec3d(20, -12, 0), Y, Z, 24, 6);
    plane(Vec3d(-5, -12, 0), Vec3d(0.6, 0.8, 0), Z, 8, 4);  // slanted inner wall
    plane(Vec3d(8, 3, 0), Vec3d(0.8, -0.6, 0), Z, 6, 4);
    for (double x : {-12.0, 0.0, 12.0}) {  // pillars
      plane(Vec3d(x, 5, 0), X, Z, 1, 5);
      plane(Vec3d(x, 5, 0), Y, Z, 1, 5);
    }
    plane(Vec3d(-6, -6, 2), Vec3d(0.7, 0, 0.71414), Y, 3, 4);  // a ramp
    return out;
  }
};

/// The frames of a sensor at poses T_world_sensor, in the sensor's body frame.
inline std::vector<std::vector<Vec3d>> room_frames(const std::vector<Isometry3d>& poses,
                                                   double spacing, double noise,
                                                   std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Room room;
  std::vector<std::vector<Vec3d>> frames;
  for (const Isometry3d& T : poses) {
    const auto world = room.sample(T.translation(), 25.0, spacing, noise, rng);
    std::vector<Vec3d> body;
    body.reserve(world.size());
    const Isometry3d inv = T.inverse();
    for (const Vec3d& p : world) body.push_back(inv * p);
    frames.push_back(std::move(body));
  }
  return frames;
}

/// Poses along a gentle curve through the room, `step` metres apart.
inline std::vector<Isometry3d> room_path(std::size_t n, double step, double start_x = -8.0) {
  std::vector<Isometry3d> out;
  for (std::size_t k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) * step;
    Isometry3d T = Isometry3d::Identity();
    T.translation() = Vec3d(start_x + s, 0.5 * std::sin(0.2 * s) - 2.0, 1.8);
    T.linear() = ulc::so3_exp(Vec3d(0.01 * std::sin(s), 0.02, 0.05 * s));
    out.push_back(T);
  }
  return out;
}

}  // namespace hots_test
