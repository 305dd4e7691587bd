// Analytic primitives the simulated world is made of, and their ray intersections.
//
// Conventions this header owns:
//   - World frame: metres, z up. Rays have a unit direction; t is the distance along it.
//   - A primitive reports the nearest intersection with t in [ray.t_min, t_max), its unit
//     normal (any orientation: users take |cos|) and the surface reflectivity in [0, 1].
//   - Hits from inside a solid (a ray starting in a box) report the exit face: the simulator
//     never starts rays inside solids, but a valid answer beats a silent miss.
//   - PorousEllipsoid is a volume (a tree canopy): a ray entering it stops at an exponentially
//     distributed depth (mean 1 / density) drawn from the ray's key and the primitive's id,
//     so the same ray always stops at the same leaf, and different rays see through gaps.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "ulc/core/types.hpp"
#include "ulc/sim/random.hpp"

namespace ulc::sim {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Ray {
  Vec3d origin = Vec3d::Zero();
  Vec3d dir = Vec3d::UnitX();  ///< unit length
  double t_min = 0.0;
  double t_max = kInfinity;
  std::uint64_t key = 0;  ///< per-ray random key (porous volumes draw their depth from it)
};

struct SurfaceHit {
  double t = kInfinity;
  Vec3d normal = Vec3d::UnitZ();
  float reflectivity = 0.0f;
};

struct Aabb {
  Vec3d lo = Vec3d::Constant(kInfinity);
  Vec3d hi = Vec3d::Constant(-kInfinity);

  void extend(const Vec3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void extend(const Aabb& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  bool valid() const { return (lo.array() <= hi.array()).all(); }
  Vec3d center() const { return 0.5 * (lo + hi); }
  double half_area() const {
    if (!valid()) return 0.0;
    const Vec3d e = hi - lo;
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  }
};

/// A box with arbitrary orientation; axis-aligned boxes have identity axes.
struct OrientedBox {
  Vec3d center = Vec3d::Zero();
  Mat3d axes = Mat3d::Identity();  ///< columns: the box's local x, y, z in the world
  Vec3d half = Vec3d::Constant(0.5);
  float reflectivity = 0.5f;
  bool aligned = false;  ///< axes are exactly the identity (set by make_aligned_if_possible)

  Aabb bounds() const {
    const Vec3d extent = axes.cwiseAbs() * half;
    return Aabb{center - extent, center + extent};
  }

  /// When the axes are a signed permutation (a box turned by multiples of 90 degrees), the
  /// same box is axis-aligned: rewrite it so, and skip the rotations when intersecting.
  void make_aligned_if_possible() {
    Vec3d h;
    for (int r = 0; r < 3; ++r) {
      int hits = 0;
      for (int c = 0; c < 3; ++c) {
        const double v = std::abs(axes(r, c));
        if (std::abs(v - 1.0) < 1e-12) {
          h[r] = half[c];
          ++hits;
        } else if (v > 1e-12) {
          return;
        }
      }
      if (hits != 1) return;
    }
    half = h;
    axes = Mat3d::Identity();
    aligned = true;
  }

  bool intersect(const Ray& ray, double t_max, SurfaceHit& hit) const {
    const Vec3d o =
        aligned ? Vec3d(ray.origin - center) : Vec3d(axes.transpose() * (ray.origin - center));
    const Vec3d d = aligned ? ray.dir : Vec3d(axes.transpose() * ray.dir);
    double t_enter = -kInfinity, t_exit = kInfinity;
    int enter_axis = 0, exit_axis = 0;
    double enter_sign = 1.0, exit_sign = 1.0;
    for (int a = 0; a < 3; ++a) {
      if (d[a] == 0.0) {
        if (o[a] < -half[a] || o[a] > half[a]) return false;
        continue;
      }
      const double inv = 1.0 / d[a];
      double t0 = (-half[a] - o[a]) * inv, t1 = (half[a] - o[a]) * inv;
      // Entering through the face whose outward normal opposes the direction.
      double s0 = -1.0, s1 = 1.0;
      if (t0 > t1) {
        std::swap(t0, t1);
        std::swap(s0, s1);
      }
      if (t0 > t_enter) {
        t_enter = t0;
        enter_axis = a;
        enter_sign = s0;
      }
      if (t1 < t_exit) {
        t_exit = t1;
        exit_axis = a;
        exit_sign = s1;
      }
      if (t_enter > t_exit) return false;
    }
    if (t_enter >= ray.t_min && t_enter < t_max) {
      hit.t = t_enter;
      hit.normal = axes.col(enter_axis) * enter_sign;
    } else if (t_enter < ray.t_min && t_exit >= ray.t_min && t_exit < t_max) {
      hit.t = t_exit;
      hit.normal = axes.col(exit_axis) * exit_sign;
    } else {
      return false;
    }
    hit.reflectivity = reflectivity;
    return true;
  }
};

/// A finite cylinder with a vertical axis (poles, trunks), capped at both ends.
struct VerticalCylinder {
  double x = 0.0, y = 0.0;
  double z0 = 0.0, z1 = 1.0;
  double radius = 0.1;
  float reflectivity = 0.5f;

  Aabb bounds() const {
    return Aabb{Vec3d(x - radius, y - radius, z0), Vec3d(x + radius, y + radius, z1)};
  }

  bool intersect(const Ray& ray, double t_max, SurfaceHit& hit) const {
    const double ox = ray.origin.x() - x, oy = ray.origin.y() - y;
    const Vec3d& d = ray.dir;
    double best = t_max;
    Vec3d normal = Vec3d::UnitZ();
    const double a = d.x() * d.x() + d.y() * d.y();
    if (a > 1e-18) {
      const double b = ox * d.x() + oy * d.y();
      const double c = ox * ox + oy * oy - radius * radius;
      const double disc = b * b - a * c;
      if (disc >= 0.0) {
        const double root = std::sqrt(disc);
        for (double t : {(-b - root) / a, (-b + root) / a}) {
          if (t < ray.t_min || t >= best) continue;
          const double z = ray.origin.z() + t * d.z();
          if (z < z0 || z > z1) continue;
          best = t;
          normal = Vec3d(ox + t * d.x(), oy + t * d.y(), 0.0) / radius;
          break;  // roots ascend: the first valid one is the nearest side hit
        }
      }
    }
    if (d.z() != 0.0) {
      for (double zc : {z0, z1}) {
        const double t = (zc - ray.origin.z()) / d.z();
        if (t < ray.t_min || t >= best) continue;
        const double px = ox + t * d.x(), py = oy + t * d.y();
        if (px * px + py * py > radius * radius) continue;
        best = t;
        normal = Vec3d::UnitZ();
      }
    }
    if (!(best < t_max)) return false;
    hit.t = best;
    hit.normal = normal;
    hit.reflectivity = reflectivity;
    return true;
  }
};

/// A triangle stored as a vertex and two edges (Moller-Trumbore).
struct Triangle {
  Vec3d v0 = Vec3d::Zero();
  Vec3d e1 = Vec3d::UnitX();
  Vec3d e2 = Vec3d::UnitY();
  float reflectivity = 0.5f;

  static Triangle from_vertices(const Vec3d& a, const Vec3d& b, const Vec3d& c, float refl) {
    return Triangle{a, b - a, c - a, refl};
  }

  Aabb bounds() const {
    Aabb box;
    box.extend(v0);
    box.extend(v0 + e1);
    box.extend(v0 + e2);
    return box;
  }

  bool intersect(const Ray& ray, double t_max, SurfaceHit& hit) const {
    const Vec3d p = ray.dir.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-14) return false;  // parallel to the plane
    const double inv = 1.0 / det;
    const Vec3d s = ray.origin - v0;
    const double u = s.dot(p) * inv;
    if (u < 0.0 || u > 1.0) return false;
    const Vec3d q = s.cross(e1);
    const double v = ray.dir.dot(q) * inv;
    if (v < 0.0 || u + v > 1.0) return false;
    const double t = e2.dot(q) * inv;
    if (t < ray.t_min || t >= t_max) return false;
    hit.t = t;
    hit.normal = e1.cross(e2).normalized();
    hit.reflectivity = reflectivity;
    return true;
  }
};

/// An axis-aligned ellipsoidal volume that stops rays at a random depth (a tree canopy).
struct PorousEllipsoid {
  Vec3d center = Vec3d::Zero();
  Vec3d radii = Vec3d::Ones();
  double density = 1.0;  ///< expected stops per metre inside the volume
  float reflectivity = 0.4f;

  Aabb bounds() const { return Aabb{center - radii, center + radii}; }

  /// `id` distinguishes canopies so that one ray draws independent depths in each.
  bool intersect(const Ray& ray, double t_max, std::uint64_t id, SurfaceHit& hit) const {
    const Vec3d o = (ray.origin - center).cwiseQuotient(radii);
    const Vec3d d = ray.dir.cwiseQuotient(radii);
    const double a = d.squaredNorm();
    const double b = o.dot(d);
    const double c = o.squaredNorm() - 1.0;
    const double disc = b * b - a * c;
    if (disc <= 0.0) return false;
    const double root = std::sqrt(disc);
    const double t0 = std::max((-b - root) / a, ray.t_min);
    const double t1 = (-b + root) / a;
    if (t0 >= t1) return false;
    const double u = unit_double(hash_key(ray.key, id, 0x7ca9a3f1ULL));
    const double t = t0 - std::log1p(-u) / density;
    if (t >= t1 || t >= t_max) return false;
    // Leaves face every way: use the direction from the centre, a stand-in that varies
    // smoothly across the canopy; at the centre itself, face the ray.
    const Vec3d from_center = (ray.origin + t * ray.dir - center).cwiseQuotient(radii);
    const double len = from_center.norm();
    hit.t = t;
    hit.normal = len > 1e-9 ? Vec3d(from_center / len) : Vec3d(-ray.dir);
    hit.reflectivity = reflectivity;
    return true;
  }
};

}  // namespace ulc::sim
