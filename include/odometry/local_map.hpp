// LocalMap: the incremental, bounded map a LiDAR's scans register against (odometry, JEEP).
//
// Conventions this header owns:
//   - Points live in voxels of edge voxel_size (voxel.hpp keys). A voxel keeps at most
//     max_points_per_voxel points, and a new point only when it is at least min_point_distance
//     from every point the voxel holds: density is bounded, and a parked sensor adds nothing.
//   - Every point carries a plane: PCA over its normal_k nearest map points in the 3x3x3 voxel
//     block around it (normals.hpp's covariance and planarity), usable when planarity >=
//     min_planarity. A new point is fitted when it arrives; all of a voxel's points are refitted
//     when the voxel has doubled its count since their last fit, and when it becomes full, so
//     early planes improve as the map fills in at O(1) amortised fits per point.
//   - Bounded extent: voxels whose centre is further than max_distance from the latest sensor
//     position are dropped (checked each time the sensor has moved prune_step since the last
//     check). Dropping rebuilds the map in insertion order.
//   - find_plane (the registration target interface, registration_types.hpp): the nearest
//     point with a usable plane within the gate, searching the voxels the gate can reach
//     (nearest voxels first, pruned by box distance). Ties go to the first point found in a
//     fixed visiting order, so answers do not depend on threads.
//   - Insertion is serial and in input order; plane fits run in parallel, one point each: the
//     map is the same for any number of threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "odometry/options.hpp"
#include "ulc/core/registration_types.hpp"
#include "ulc/core/types.hpp"
#include "ulc/core/voxel.hpp"

namespace odometry {

using ulc::Isometry3d;
using ulc::Mat3d;
using ulc::PlaneMatch;
using ulc::Vec3;
using ulc::Vec3d;

inline bool valid_local_map_options(const LocalMapOptions& o) {
  return o.voxel_size > 0.0 && std::isfinite(o.voxel_size) && o.max_points_per_voxel >= 1 &&
         o.max_points_per_voxel <= 65535 && o.min_point_distance >= 0.0 && o.max_distance > 0.0 &&
         o.prune_step > 0.0 && o.normal_k >= 3;
}

template <typename S>
class LocalMap {
 public:
  using Point = Vec3<S>;

  explicit LocalMap(const LocalMapOptions& options = {}) : options_(options) {}

  const LocalMapOptions& options() const { return options_; }
  std::size_t size() const { return point_count_; }
  bool empty() const { return point_count_ == 0; }
  std::size_t voxel_count() const { return voxels_.size(); }

  void clear() {
    voxels_.clear();
    slots_.clear();
    point_count_ = 0;
    last_prune_position_.reset();
  }

  /// Adds points given in the map frame, seen from `sensor_position` (map frame).
  void insert(const std::vector<Point>& points, const Vec3d& sensor_position) {
    const std::size_t cap = options_.max_points_per_voxel;
    const S min_sq = static_cast<S>(options_.min_point_distance * options_.min_point_distance);
    std::vector<std::size_t> touched;                         // voxel positions, first touch order
    std::vector<std::uint32_t> first_new(voxels_.size(), 0);  // count before this insert
    std::vector<std::uint8_t> is_touched(voxels_.size(), 0);
    for (const Point& p : points) {
      const auto key = ulc::make_voxel_key(p, options_.voxel_size);
      if (!key) continue;
      const auto [pos, inserted] = voxels_.try_emplace(*key, Voxel{});
      if (inserted) {
        slots_.resize(slots_.size() + cap, Slot{Point::Zero(), Point::Zero()});
        first_new.push_back(0);
        is_touched.push_back(0);
      }
      Voxel& voxel = voxels_.at_position(pos).value;
      if (voxel.count >= cap) continue;
      const Slot* block = &slots_[pos * cap];
      bool far_enough = true;
      for (std::size_t i = 0; i < voxel.count && far_enough; ++i)
        far_enough = (block[i].point - p).squaredNorm() >= min_sq;
      if (!far_enough) continue;
      if (!is_touched[pos]) {
        is_touched[pos] = 1;
        first_new[pos] = voxel.count;
        touched.push_back(pos);
      }
      slots_[pos * cap + voxel.count].point = p;
      ++voxel.count;
      ++point_count_;
    }
    // Which points to fit: the new ones, or the whole voxel when it doubled or filled up.
    std::vector<std::pair<std::size_t, std::size_t>> work;  // (voxel position, first point)
    work.reserve(touched.size());
    for (std::size_t pos : touched) {
      Voxel& voxel = voxels_.at_position(pos).value;
      const bool refit_all = voxel.count >= 2 * voxel.fitted || voxel.count == cap;
      work.emplace_back(pos, refit_all ? 0 : first_new[pos]);
      if (refit_all) voxel.fitted = voxel.count;
    }
    fit_planes(work);
    prune(sensor_position);
  }

  /// The registration target interface (see the top of this file).
  bool find_plane(const Vec3d& query, double max_distance, PlaneMatch& out) const {
    if (voxels_.empty() || !(max_distance > 0.0)) return false;
    const auto key = ulc::make_voxel_key(query, options_.voxel_size);
    if (!key) return false;
    const double v = options_.voxel_size;
    // The query is inside the centre voxel, so shell s is at least (s - 1) v away: shells
    // beyond ceil(gate / v) hold nothing strictly closer than the gate.
    const int reach = static_cast<int>(std::ceil(max_distance / v));
    double best = max_distance * max_distance;
    const Slot* best_slot = nullptr;
    int shell = 0;
    if (interior(*key)) {
      scan_block(*key, query, best, best_slot);  // shells 0 and 1, the common case
      shell = 2;
    }
    // Further shells (a gate wider than a voxel), by growing Chebyshev distance: once a shell's
    // closest possible box is further than the best, no later shell can do better.
    for (; shell <= reach; ++shell) {
      if (shell >= 1 && (shell - 1) * v * (shell - 1) * v > best) break;
      scan_shell(*key, shell, query, best, best_slot);
    }
    if (!best_slot) return false;
    out.point = best_slot->point.template cast<double>();
    out.normal = best_slot->normal.template cast<double>();
    return true;
  }

  /// Every point, voxel by voxel in insertion order.
  std::vector<Point> points() const {
    std::vector<Point> out;
    out.reserve(point_count_);
    for_each_slot([&](const Slot& s) { out.push_back(s.point); });
    return out;
  }

  /// The planes' normals, aligned with points() (zero where no usable plane was found).
  std::vector<Point> normals() const {
    std::vector<Point> out;
    out.reserve(point_count_);
    for_each_slot([&](const Slot& s) { out.push_back(s.normal); });
    return out;
  }

 private:
  struct Voxel {
    std::uint32_t count = 0;
    std::uint32_t fitted = 0;  ///< count when all its points were last fitted
  };
  /// A point and its plane's normal side by side: one cache line serves both in a query.
  struct Slot {
    Point point;
    Point normal;  ///< zero: no usable plane
  };

  template <class F>
  void for_each_slot(F&& f) const {
    const std::size_t cap = options_.max_points_per_voxel;
    for (std::size_t v = 0; v < voxels_.size(); ++v)
      for (std::size_t i = 0; i < voxels_.at_position(v).value.count; ++i) f(slots_[v * cap + i]);
  }

  /// The 26 neighbour offsets: 6 faces, 12 edges, 8 corners (nearest boxes first on average).
  static constexpr int kNeighbours[26][3] = {
      {-1, 0, 0},  {1, 0, 0},   {0, -1, 0}, {0, 1, 0},   {0, 0, -1},   {0, 0, 1},   {-1, -1, 0},
      {-1, 1, 0},  {1, -1, 0},  {1, 1, 0},  {-1, 0, -1}, {-1, 0, 1},   {1, 0, -1},  {1, 0, 1},
      {0, -1, -1}, {0, -1, 1},  {0, 1, -1}, {0, 1, 1},   {-1, -1, -1}, {-1, -1, 1}, {-1, 1, -1},
      {-1, 1, 1},  {1, -1, -1}, {1, -1, 1}, {1, 1, -1},  {1, 1, 1}};

  /// Every neighbour key of k fits in int32.
  static bool interior(const ulc::VoxelKey& k) {
    constexpr std::int32_t lo = std::numeric_limits<std::int32_t>::min();
    constexpr std::int32_t hi = std::numeric_limits<std::int32_t>::max();
    return k.x > lo && k.x < hi && k.y > lo && k.y < hi && k.z > lo && k.z < hi;
  }

  static std::optional<ulc::VoxelKey> offset(const ulc::VoxelKey& k, int dx, int dy, int dz) {
    const std::int64_t x = std::int64_t{k.x} + dx, y = std::int64_t{k.y} + dy,
                       z = std::int64_t{k.z} + dz;
    constexpr std::int64_t lo = std::numeric_limits<std::int32_t>::min();
    constexpr std::int64_t hi = std::numeric_limits<std::int32_t>::max();
    if (x < lo || x > hi || y < lo || y > hi || z < lo || z > hi) return std::nullopt;
    return ulc::VoxelKey{static_cast<std::int32_t>(x), static_cast<std::int32_t>(y),
                         static_cast<std::int32_t>(z)};
  }

  /// Squared distance from q to the voxel's box.
  double box_sq_distance(const Vec3d& q, const ulc::VoxelKey& k) const {
    const Vec3d lo = ulc::voxel_corner(k, options_.voxel_size);
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double low = lo[a], high = lo[a] + options_.voxel_size;
      const double d = q[a] < low ? low - q[a] : (q[a] > high ? q[a] - high : 0.0);
      d2 += d * d;
    }
    return d2;
  }

  /// The centre voxel of `key`, then its 26 neighbours, faces first, each skipped when its box is
  /// further than the best so far. Every neighbour key must fit (interior(key)).
  void scan_block(const ulc::VoxelKey& key, const Vec3d& q, double& best,
                  const Slot*& best_slot) const {
    const double v = options_.voxel_size;
    const auto centre = voxels_.position(key);
    if (centre) scan_voxel(*centre, q, best, best_slot);
    const Vec3d lo = ulc::voxel_corner(key, v);
    double below[3], above[3];
    for (int a = 0; a < 3; ++a) {
      below[a] = (q[a] - lo[a]) * (q[a] - lo[a]);
      above[a] = (lo[a] + v - q[a]) * (lo[a] + v - q[a]);
    }
    for (const auto& o : kNeighbours) {
      double d2 = 0.0;
      for (int a = 0; a < 3; ++a) d2 += o[a] < 0 ? below[a] : (o[a] > 0 ? above[a] : 0.0);
      if (d2 > best) continue;
      const auto pos = voxels_.position(ulc::VoxelKey{key.x + o[0], key.y + o[1], key.z + o[2]});
      if (pos) scan_voxel(*pos, q, best, best_slot);
    }
  }

  /// The voxels at Chebyshev distance `shell` from `key`, each skipped when its box is further
  /// than the best so far.
  void scan_shell(const ulc::VoxelKey& key, int shell, const Vec3d& q, double& best,
                  const Slot*& best_slot) const {
    for (int dx = -shell; dx <= shell; ++dx)
      for (int dy = -shell; dy <= shell; ++dy)
        for (int dz = -shell; dz <= shell; ++dz) {
          if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != shell) continue;
          const auto neighbour = offset(key, dx, dy, dz);
          if (!neighbour || box_sq_distance(q, *neighbour) > best) continue;
          const auto pos = voxels_.position(*neighbour);
          if (pos) scan_voxel(*pos, q, best, best_slot);
        }
  }

  void scan_voxel(std::size_t pos, const Vec3d& q, double& best, const Slot*& best_slot) const {
    const std::size_t cap = options_.max_points_per_voxel;
    const std::size_t count = voxels_.at_position(pos).value.count;
    const Slot* block = &slots_[pos * cap];
    for (std::size_t i = 0; i < count; ++i) {
      if (block[i].normal.squaredNorm() == S(0)) continue;  // no usable plane
      const double d2 = (block[i].point.template cast<double>() - q).squaredNorm();
      if (d2 < best) {
        best = d2;
        best_slot = &block[i];
      }
    }
  }

  /// PCA planes of the points [first, count) of each listed voxel.
  void fit_planes(const std::vector<std::pair<std::size_t, std::size_t>>& work) {
    const std::size_t cap = options_.max_points_per_voxel;
    std::vector<std::size_t> slots;  // every point to fit, flattened: even parallel chunks
    for (const auto& [pos, first] : work)
      for (std::size_t i = first; i < voxels_.at_position(pos).value.count; ++i)
        slots.push_back(pos * cap + i);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, slots.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        std::vector<std::pair<S, std::size_t>> candidates;
                        candidates.reserve(27 * cap);
                        for (std::size_t r = range.begin(); r != range.end(); ++r) {
                          Slot& slot = slots_[slots[r]];
                          slot.normal = fit_plane(slot.point, candidates);
                        }
                      });
  }

  /// The normal of the plane through p's normal_k nearest map points, searched in the voxels
  /// within half a voxel of p (enough for any density the cap allows); zero if not planar.
  Point fit_plane(const Point& p, std::vector<std::pair<S, std::size_t>>& candidates) const {
    const std::size_t cap = options_.max_points_per_voxel;
    const Vec3d q = p.template cast<double>();
    const auto key = ulc::make_voxel_key(p, options_.voxel_size);
    if (!key) return Point::Zero();
    const double reach = 0.25 * options_.voxel_size * options_.voxel_size;
    candidates.clear();
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto n = offset(*key, dx, dy, dz);
          if (!n || box_sq_distance(q, *n) > reach) continue;
          const auto np = voxels_.position(*n);
          if (!np) continue;
          const std::size_t c = voxels_.at_position(*np).value.count;
          for (std::size_t i = 0; i < c; ++i) {
            const std::size_t s = *np * cap + i;
            candidates.emplace_back((slots_[s].point - p).squaredNorm(), s);
          }
        }
    return fit_nearest(candidates);
  }

  /// PCA of the normal_k nearest candidates (squared distance, slot).
  Point fit_nearest(std::vector<std::pair<S, std::size_t>>& candidates) const {
    if (candidates.size() < 3) return Point::Zero();
    const std::size_t n = std::min(options_.normal_k, candidates.size());
    std::nth_element(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(n - 1),
                     candidates.end());
    Vec3d mean = Vec3d::Zero();
    for (std::size_t i = 0; i < n; ++i)
      mean += slots_[candidates[i].second].point.template cast<double>();
    mean /= static_cast<double>(n);
    Mat3d cov = Mat3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3d d = slots_[candidates[i].second].point.template cast<double>() - mean;
      cov.noalias() += d * d.transpose();
    }
    cov /= static_cast<double>(n);
    Eigen::SelfAdjointEigenSolver<Mat3d> eig;
    eig.computeDirect(cov);  // closed form: fast, and ample for a plane's normal
    const Vec3d l = eig.eigenvalues();
    if (!(l[2] > 0.0) || !(l[1] > 1e-6 * l[2])) return Point::Zero();
    const double planarity = (l[1] - std::max(l[0], 0.0)) / l[1];
    if (planarity < options_.min_planarity) return Point::Zero();
    return eig.eigenvectors().col(0).normalized().template cast<S>();
  }

  void prune(const Vec3d& sensor_position) {
    if (last_prune_position_ &&
        (sensor_position - *last_prune_position_).norm() < options_.prune_step)
      return;
    last_prune_position_ = sensor_position;
    const double v = options_.voxel_size;
    const double limit = options_.max_distance * options_.max_distance;
    auto far = [&](const ulc::VoxelKey& k) {
      const Vec3d centre = ulc::voxel_corner(k, v) + Vec3d::Constant(v / 2);
      return (centre - sensor_position).squaredNorm() > limit;
    };
    bool any_far = false;
    for (const auto& e : voxels_) any_far = any_far || far(e.key);
    if (!any_far) return;
    const std::size_t cap = options_.max_points_per_voxel;
    ulc::VoxelMap<Voxel> kept;
    std::vector<Slot> slots;
    point_count_ = 0;
    for (std::size_t pos = 0; pos < voxels_.size(); ++pos) {
      const auto& e = voxels_.at_position(pos);
      if (far(e.key)) continue;
      kept.try_emplace(e.key, e.value);
      slots.insert(slots.end(), slots_.begin() + static_cast<std::ptrdiff_t>(pos * cap),
                   slots_.begin() + static_cast<std::ptrdiff_t>((pos + 1) * cap));
      point_count_ += e.value.count;
    }
    voxels_ = std::move(kept);
    slots_ = std::move(slots);
  }

  LocalMapOptions options_;
  ulc::VoxelMap<Voxel> voxels_;
  std::vector<Slot> slots_;  ///< max_points_per_voxel slots per voxel, by voxel position
  std::size_t point_count_ = 0;
  std::optional<Vec3d> last_prune_position_;
};

}  // namespace odometry
