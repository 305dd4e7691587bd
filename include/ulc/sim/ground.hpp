// Ground: a smooth low-frequency height field, and its triangulated grid with small roughness,
// ray-cast by walking the grid cells the ray crosses (2D DDA) instead of through the BVH.
//
// Conventions this header owns:
//   - GroundRelief::height(x, y) is the analytic surface the vehicle drives on: a sum of a few
//     long-wavelength plane waves (80..300 m), a few decimetres high, so slopes stay below ~3%.
//   - GroundGrid samples it on a square grid and adds per-vertex roughness (drawn from the
//     vertex's integer coordinates, so the result does not depend on construction order). Each
//     cell is two triangles, the diagonal alternating like a checkerboard so the mesh has no
//     preferred direction. The vehicle rides the analytic surface; the two differ by the
//     roughness and the (millimetre) linear-interpolation error.
//   - intersect() visits cells in ray order and tests a cell's triangles only when the ray's
//     height range over the cell overlaps the cell's height range; the first hit found is the
//     nearest. triangles() gives the same surface as plain triangles (brute-force tests).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "ulc/sim/primitives.hpp"
#include "ulc/sim/random.hpp"

namespace ulc::sim {

class GroundRelief {
 public:
  struct Wave {
    double kx, ky;  ///< wave vector, rad/m
    double amplitude;
    double phase;
  };

  GroundRelief() = default;  ///< flat ground at z = 0

  /// Random relief: `waves` plane waves with wavelengths in [80, 300] m whose amplitudes sum to
  /// about `total_amplitude` metres.
  static GroundRelief random(std::uint64_t key, double total_amplitude, int waves = 4) {
    GroundRelief g;
    CounterRng rng(key);
    for (int i = 0; i < waves; ++i) {
      const double wavelength = rng.uniform(80.0, 300.0);
      const double dir = rng.uniform(0.0, 6.283185307179586);
      const double k = 6.283185307179586 / wavelength;
      g.waves_.push_back(Wave{k * std::cos(dir), k * std::sin(dir),
                              total_amplitude / waves * rng.uniform(0.5, 1.5),
                              rng.uniform(0.0, 6.283185307179586)});
    }
    return g;
  }

  double height(double x, double y) const {
    double z = 0.0;
    for (const Wave& w : waves_) z += w.amplitude * std::sin(w.kx * x + w.ky * y + w.phase);
    return z;
  }

  /// (dz/dx, dz/dy)
  Eigen::Vector2d gradient(double x, double y) const {
    Eigen::Vector2d g = Eigen::Vector2d::Zero();
    for (const Wave& w : waves_) {
      const double c = w.amplitude * std::cos(w.kx * x + w.ky * y + w.phase);
      g.x() += c * w.kx;
      g.y() += c * w.ky;
    }
    return g;
  }

 private:
  std::vector<Wave> waves_;
};

struct GroundMeshSpec {
  double x0 = 0, y0 = 0, x1 = 100, y1 = 100;  ///< covered rectangle
  double spacing = 3.0;                       ///< grid step, metres
  double roughness = 0.01;                    ///< per-vertex height noise sigma, metres
  std::uint64_t key = 0;                      ///< roughness stream
};

class GroundGrid {
 public:
  GroundGrid() = default;

  /// `reflectivity(x, y)` gives each cell's material at its centre.
  GroundGrid(const GroundRelief& relief, const GroundMeshSpec& spec,
             const std::function<float(double, double)>& reflectivity)
      : x0_(spec.x0), y0_(spec.y0), step_(spec.spacing) {
    nx_ = std::max<long>(1, static_cast<long>(std::ceil((spec.x1 - spec.x0) / step_)));
    ny_ = std::max<long>(1, static_cast<long>(std::ceil((spec.y1 - spec.y0) / step_)));
    z_.resize(static_cast<std::size_t>((nx_ + 1) * (ny_ + 1)));
    for (long j = 0; j <= ny_; ++j)
      for (long i = 0; i <= nx_; ++i) {
        const double x = x0_ + static_cast<double>(i) * step_;
        const double y = y0_ + static_cast<double>(j) * step_;
        double z = relief.height(x, y);
        if (spec.roughness > 0.0) {
          CounterRng rng(hash_key(spec.key, static_cast<std::uint64_t>(i) + 0x100000000ULL,
                                  static_cast<std::uint64_t>(j) + 0x100000000ULL));
          z += spec.roughness * rng.normal();
        }
        z_[vertex(i, j)] = z;
      }
    cell_lo_.resize(static_cast<std::size_t>(nx_ * ny_));
    cell_hi_.resize(cell_lo_.size());
    refl_.resize(cell_lo_.size());
    z_min_ = kInfinity;
    z_max_ = -kInfinity;
    for (long j = 0; j < ny_; ++j)
      for (long i = 0; i < nx_; ++i) {
        const double a = z_[vertex(i, j)], b = z_[vertex(i + 1, j)];
        const double c = z_[vertex(i + 1, j + 1)], d = z_[vertex(i, j + 1)];
        const std::size_t k = cell(i, j);
        cell_lo_[k] = std::min(std::min(a, b), std::min(c, d)) - 1e-6;
        cell_hi_[k] = std::max(std::max(a, b), std::max(c, d)) + 1e-6;
        z_min_ = std::min(z_min_, cell_lo_[k]);
        z_max_ = std::max(z_max_, cell_hi_[k]);
        refl_[k] = reflectivity(x0_ + (i + 0.5) * step_, y0_ + (j + 0.5) * step_);
      }
  }

  bool empty() const { return z_.empty(); }
  std::size_t cell_count() const { return cell_lo_.size(); }

  /// Nearest ground hit with t in [ray.t_min, t_max).
  bool intersect(const Ray& ray, double t_max, SurfaceHit& hit) const {
    if (z_.empty()) return false;
    const Vec3d& o = ray.origin;
    const Vec3d& d = ray.dir;
    // Clip to the grid's box: x, y extent and the height range.
    double ta = ray.t_min, tb = t_max;
    const double lo[3] = {x0_, y0_, z_min_};
    const double hi[3] = {x0_ + nx_ * step_, y0_ + ny_ * step_, z_max_};
    for (int a = 0; a < 3; ++a) {
      if (d[a] == 0.0) {
        if (o[a] < lo[a] || o[a] > hi[a]) return false;
        continue;
      }
      double t0 = (lo[a] - o[a]) / d[a], t1 = (hi[a] - o[a]) / d[a];
      if (t0 > t1) std::swap(t0, t1);
      ta = std::max(ta, t0);
      tb = std::min(tb, t1);
      if (ta > tb) return false;
    }
    // Walk the cells from ta to tb.
    const double px = o.x() + ta * d.x(), py = o.y() + ta * d.y();
    long i = std::clamp(static_cast<long>(std::floor((px - x0_) / step_)), 0L, nx_ - 1);
    long j = std::clamp(static_cast<long>(std::floor((py - y0_) / step_)), 0L, ny_ - 1);
    const long si = d.x() > 0.0 ? 1 : -1, sj = d.y() > 0.0 ? 1 : -1;
    const double dtx = d.x() != 0.0 ? step_ / std::abs(d.x()) : kInfinity;
    const double dty = d.y() != 0.0 ? step_ / std::abs(d.y()) : kInfinity;
    double tx = d.x() != 0.0 ? (x0_ + (i + (si > 0 ? 1 : 0)) * step_ - o.x()) / d.x() : kInfinity;
    double ty = d.y() != 0.0 ? (y0_ + (j + (sj > 0 ? 1 : 0)) * step_ - o.y()) / d.y() : kInfinity;
    double t_cell = ta;
    for (;;) {
      const double t_exit = std::min(std::min(tx, ty), tb);
      const double za = o.z() + t_cell * d.z(), zb = o.z() + t_exit * d.z();
      const std::size_t k = cell(i, j);
      if (std::max(za, zb) >= cell_lo_[k] && std::min(za, zb) <= cell_hi_[k] &&
          test_cell(ray, i, j, t_max, hit))
        return true;
      if (t_exit >= tb) return false;
      if (tx < ty) {
        i += si;
        t_cell = tx;
        tx += dtx;
      } else {
        j += sj;
        t_cell = ty;
        ty += dty;
      }
      if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return false;
    }
  }

  /// The same surface as triangles (for brute-force references).
  std::vector<Triangle> triangles() const {
    std::vector<Triangle> out;
    for (long j = 0; j < ny_; ++j)
      for (long i = 0; i < nx_; ++i) {
        Triangle t0, t1;
        cell_triangles(i, j, t0, t1);
        out.push_back(t0);
        out.push_back(t1);
      }
    return out;
  }

 private:
  std::size_t vertex(long i, long j) const { return static_cast<std::size_t>(j * (nx_ + 1) + i); }
  std::size_t cell(long i, long j) const { return static_cast<std::size_t>(j * nx_ + i); }
  Vec3d corner(long i, long j) const {
    return Vec3d(x0_ + static_cast<double>(i) * step_, y0_ + static_cast<double>(j) * step_,
                 z_[vertex(i, j)]);
  }

  void cell_triangles(long i, long j, Triangle& t0, Triangle& t1) const {
    const Vec3d a = corner(i, j), b = corner(i + 1, j), c = corner(i + 1, j + 1),
                d = corner(i, j + 1);
    const float r = refl_[cell(i, j)];
    if (((i + j) & 1) == 0) {
      t0 = Triangle::from_vertices(a, b, c, r);
      t1 = Triangle::from_vertices(a, c, d, r);
    } else {
      t0 = Triangle::from_vertices(a, b, d, r);
      t1 = Triangle::from_vertices(b, c, d, r);
    }
  }

  /// The cell's two triangles, intersected as planes z = alpha + beta u + gamma v in the cell's
  /// unit coordinates (u, v) and clipped to their halves of the cell: the same surface as
  /// cell_triangles, at a fraction of the cost of two general triangle tests.
  bool test_cell(const Ray& ray, long i, long j, double t_max, SurfaceHit& hit) const {
    const double za = z_[vertex(i, j)], zb = z_[vertex(i + 1, j)];
    const double zc = z_[vertex(i + 1, j + 1)], zd = z_[vertex(i, j + 1)];
    const double inv_step = 1.0 / step_;
    const double u0 = (ray.origin.x() - (x0_ + static_cast<double>(i) * step_)) * inv_step;
    const double v0 = (ray.origin.y() - (y0_ + static_cast<double>(j) * step_)) * inv_step;
    const double du = ray.dir.x() * inv_step, dv = ray.dir.y() * inv_step;
    const bool even = ((i + j) & 1) == 0;
    // Planes and halves: even cells split along u = v, odd cells along u + v = 1.
    const double planes[2][3] = {{za, zb - za, even ? zc - zb : zd - za},
                                 {even ? za : zb + zd - zc, zc - zd, even ? zd - za : zc - zb}};
    constexpr double kEdge = 1e-9;  // closed cells: no cracks along shared edges
    bool found = false;
    for (int k = 0; k < 2; ++k) {
      const double alpha = planes[k][0], beta = planes[k][1], gamma = planes[k][2];
      const double denom = ray.dir.z() - beta * du - gamma * dv;
      if (std::abs(denom) < 1e-15) continue;
      const double t = (alpha + beta * u0 + gamma * v0 - ray.origin.z()) / denom;
      if (!(t >= ray.t_min && t < t_max)) continue;
      const double u = u0 + du * t, v = v0 + dv * t;
      if (u < -kEdge || u > 1.0 + kEdge || v < -kEdge || v > 1.0 + kEdge) continue;
      const double side = even ? v - u : u + v - 1.0;  // <= 0: first triangle, >= 0: second
      if (k == 0 ? side > kEdge : side < -kEdge) continue;
      t_max = t;
      hit.t = t;
      hit.normal = Vec3d(-beta * inv_step, -gamma * inv_step, 1.0).normalized();
      hit.reflectivity = refl_[cell(i, j)];
      found = true;
    }
    return found;
  }

  double x0_ = 0.0, y0_ = 0.0, step_ = 1.0;
  long nx_ = 0, ny_ = 0;
  std::vector<double> z_;
  std::vector<double> cell_lo_, cell_hi_;
  std::vector<float> refl_;
  double z_min_ = 0.0, z_max_ = 0.0;
};

}  // namespace ulc::sim
