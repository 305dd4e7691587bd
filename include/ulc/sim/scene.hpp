// The simulated world's geometry: analytic primitives under one BVH, queried by closest hit.
//
// Conventions this header owns:
//   - Add primitives, then call build() once; intersect() is const and thread-safe.
//   - build() reorders each primitive array into BVH leaf order (cache locality), so indices
//     returned by add_* are only meaningful before build(). Same adds, same scene, same bits.
//   - Dispatch is a switch on a 2-bit kind packed into each leaf slot: no virtual calls.
//   - The ground is a separate height-field grid (ground.hpp), tested first: its hit bounds
//     the BVH traversal, and keeping its many small triangles out of the BVH keeps the tree
//     shallow.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "ulc/sim/bvh.hpp"
#include "ulc/sim/ground.hpp"
#include "ulc/sim/primitives.hpp"

namespace ulc::sim {

class Scene {
 public:
  enum Kind : std::uint32_t { kBox = 0, kCylinder = 1, kTriangle = 2, kCanopy = 3 };

  void add(OrientedBox b) {
    b.make_aligned_if_possible();
    push(kBox, boxes_, b);
  }
  void add(const VerticalCylinder& c) { push(kCylinder, cylinders_, c); }
  void add(const Triangle& t) { push(kTriangle, triangles_, t); }
  void add(const PorousEllipsoid& e) { push(kCanopy, canopies_, e); }

  void set_ground(GroundGrid ground) { ground_ = std::move(ground); }
  const GroundGrid& ground() const { return ground_; }

  /// An axis-aligned box from its corners.
  void add_aabb(const Vec3d& lo, const Vec3d& hi, float reflectivity) {
    add(OrientedBox{0.5 * (lo + hi), Mat3d::Identity(), 0.5 * (hi - lo), reflectivity, true});
  }

  /// Builds the BVH; call once after the last add.
  void build() {
    std::vector<Aabb> boxes;
    boxes.reserve(refs_.size());
    for (std::uint32_t r : refs_) boxes.push_back(bounds_of(r));
    bvh_.build(boxes);
    // Reorder primitives into leaf order and remember each slot's new reference.
    std::vector<OrientedBox> boxes2;
    std::vector<VerticalCylinder> cylinders2;
    std::vector<Triangle> triangles2;
    std::vector<PorousEllipsoid> canopies2;
    slots_.clear();
    slots_.reserve(refs_.size());
    for (std::uint32_t item : bvh_.items()) {
      const std::uint32_t r = refs_[item];
      const std::uint32_t i = r & kIndexMask;
      switch (r >> kKindShift) {
        case kBox:
          slots_.push_back(pack(kBox, boxes2.size()));
          boxes2.push_back(boxes_[i]);
          break;
        case kCylinder:
          slots_.push_back(pack(kCylinder, cylinders2.size()));
          cylinders2.push_back(cylinders_[i]);
          break;
        case kTriangle:
          slots_.push_back(pack(kTriangle, triangles2.size()));
          triangles2.push_back(triangles_[i]);
          break;
        default:
          slots_.push_back(pack(kCanopy, canopies2.size()));
          canopies2.push_back(canopies_[i]);
          break;
      }
    }
    boxes_.swap(boxes2);
    cylinders_.swap(cylinders2);
    triangles_.swap(triangles2);
    canopies_.swap(canopies2);
    refs_ = slots_;
    built_ = true;
  }

  bool built() const { return built_; }
  std::size_t size() const { return refs_.size(); }
  std::size_t box_count() const { return boxes_.size(); }
  std::size_t cylinder_count() const { return cylinders_.size(); }
  std::size_t triangle_count() const { return triangles_.size(); }
  std::size_t canopy_count() const { return canopies_.size(); }
  const Bvh& bvh() const { return bvh_; }

  /// Closest hit with t in [ray.t_min, ray.t_max). Requires build().
  bool intersect(const Ray& ray, SurfaceHit& hit) const {
    double t_max = ray.t_max;
    bool found = ground_.intersect(ray, t_max, hit);
    if (found) t_max = hit.t;
    bvh_.traverse(ray, t_max, [&](std::uint32_t slot, double& t_best) {
      if (test(slots_[slot], ray, t_best, hit)) {
        t_best = hit.t;
        found = true;
      }
    });
    return found;
  }

  /// The same answer by testing every primitive (for tests).
  bool intersect_brute_force(const Ray& ray, SurfaceHit& hit) const {
    double t_best = ray.t_max;
    bool found = false;
    for (const Triangle& t : ground_.triangles()) {
      if (t.intersect(ray, t_best, hit)) {
        t_best = hit.t;
        found = true;
      }
    }
    for (std::uint32_t r : refs_) {
      if (test(r, ray, t_best, hit)) {
        t_best = hit.t;
        found = true;
      }
    }
    return found;
  }

  Aabb bounds() const {
    Aabb b;
    for (std::uint32_t r : refs_) b.extend(bounds_of(r));
    return b;
  }

 private:
  static constexpr std::uint32_t kKindShift = 30;
  static constexpr std::uint32_t kIndexMask = (1u << kKindShift) - 1u;

  static std::uint32_t pack(std::uint32_t kind, std::size_t index) {
    return (kind << kKindShift) | static_cast<std::uint32_t>(index);
  }

  template <class T>
  void push(std::uint32_t kind, std::vector<T>& v, const T& p) {
    refs_.push_back(pack(kind, v.size()));
    v.push_back(p);
    built_ = false;
  }

  Aabb bounds_of(std::uint32_t r) const {
    const std::uint32_t i = r & kIndexMask;
    switch (r >> kKindShift) {
      case kBox:
        return boxes_[i].bounds();
      case kCylinder:
        return cylinders_[i].bounds();
      case kTriangle:
        return triangles_[i].bounds();
      default:
        return canopies_[i].bounds();
    }
  }

  bool test(std::uint32_t r, const Ray& ray, double t_max, SurfaceHit& hit) const {
    const std::uint32_t i = r & kIndexMask;
    switch (r >> kKindShift) {
      case kBox:
        return boxes_[i].intersect(ray, t_max, hit);
      case kCylinder:
        return cylinders_[i].intersect(ray, t_max, hit);
      case kTriangle:
        return triangles_[i].intersect(ray, t_max, hit);
      default:
        return canopies_[i].intersect(ray, t_max, i, hit);
    }
  }

  std::vector<OrientedBox> boxes_;
  std::vector<VerticalCylinder> cylinders_;
  std::vector<Triangle> triangles_;
  std::vector<PorousEllipsoid> canopies_;
  std::vector<std::uint32_t> refs_;   ///< before build: insertion order; after: slot order
  std::vector<std::uint32_t> slots_;  ///< slot -> packed reference
  GroundGrid ground_;
  Bvh bvh_;
  bool built_ = false;
};

}  // namespace ulc::sim
