// A bounding volume hierarchy over axis-aligned boxes, for closest-hit ray queries.
//
// Conventions this header owns:
//   - Built once, serially, with a binned surface-area heuristic (kBins bins on the axis of
//     largest centroid spread); leaves hold at most kMaxLeaf items. Below a depth limit the
//     build switches to object-median splits, so the tree depth (and the traversal stack)
//     stays bounded whatever the input. Same input, same tree.
//   - Flat node array in depth-first order: an inner node's left child is the next node and
//     its right child is stored; 32-byte nodes with float bounds padded outwards by kPad so
//     float rounding never loses a hit (primitive tests themselves run in double).
//   - Traversal: stack-based, nearer child first, subtrees skipped once they start beyond the
//     closest hit so far. No allocation per ray; const queries are safe from many threads.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "ulc/sim/primitives.hpp"

namespace ulc::sim {

struct BvhNode {
  float box[2][3];      ///< box[0] = min corner, box[1] = max corner
  std::uint32_t index;  ///< inner: right child; leaf: first entry of items()
  std::uint32_t count;  ///< 0 for inner nodes, else the number of items in the leaf
};
static_assert(sizeof(BvhNode) == 32, "two nodes per cache line");

class Bvh {
 public:
  static constexpr int kBins = 16;
  static constexpr std::uint32_t kMaxLeaf = 2;
  /// Cost of one primitive test in node tests (an oriented box costs about four).
  static constexpr double kItemCost = 4.0;
  static constexpr int kMedianDepth = 40;  ///< deeper than this: median splits only
  static constexpr int kStackSize = 96;
  static constexpr float kPad = 2e-3f;  ///< metres; covers float rounding at km coordinates

  /// Builds over `boxes`; item i of a leaf refers to boxes[items()[i]].
  void build(const std::vector<Aabb>& boxes) {
    nodes_.clear();
    items_.resize(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) items_[i] = static_cast<std::uint32_t>(i);
    if (boxes.empty()) return;
    centroids_.resize(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) centroids_[i] = boxes[i].center();
    nodes_.reserve(2 * boxes.size() / kMaxLeaf + 1);
    build_node(boxes, 0, static_cast<std::uint32_t>(boxes.size()), 0);
    centroids_.clear();
    centroids_.shrink_to_fit();
  }

  bool empty() const { return nodes_.empty(); }
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  const std::vector<std::uint32_t>& items() const { return items_; }

  /// Visits the leaves a ray may hit, nearer first. `leaf(slot, t_max)` tests the item
  /// items()[slot] (slots of one leaf are contiguous, so callers may store their data in slot
  /// order) and lowers t_max when it finds a closer hit; subtrees beyond t_max are skipped.
  template <class LeafFn>
  void traverse(const Ray& ray, double& t_max, LeafFn&& leaf) const {
    if (nodes_.empty()) return;
    // Slab planes as t = plane * inv - origin * inv (one multiply-add per plane); the near
    // plane of each axis is known from the direction's sign, so no min/max per axis.
    Slabs r;
    for (int a = 0; a < 3; ++a) {
      const double d = ray.dir[a];
      r.inv[a] = static_cast<float>(1.0 / (std::abs(d) > 1e-12 ? d : std::copysign(1e-12, d)));
      r.oinv[a] = static_cast<float>(ray.origin[a]) * r.inv[a];
      r.near[a] = r.inv[a] < 0.0f ? 1 : 0;
    }
    const float t_lo = static_cast<float>(ray.t_min);
    struct Entry {
      std::uint32_t node;
      float t;
    };
    Entry stack[kStackSize];
    int top = 0;
    float t_root;
    if (!slab(nodes_[0], r, t_lo, limit(t_max), t_root)) return;
    std::uint32_t node = 0;
    for (;;) {
      const BvhNode& n = nodes_[node];
      if (n.count > 0) {
        for (std::uint32_t i = n.index; i < n.index + n.count; ++i) leaf(i, t_max);
      } else {
        const std::uint32_t left = node + 1, right = n.index;
        float tl, tr;
        const float t_hi = limit(t_max);
        const bool hl = slab(nodes_[left], r, t_lo, t_hi, tl);
        const bool hr = slab(nodes_[right], r, t_lo, t_hi, tr);
        if (hl && hr) {
          const bool left_first = tl <= tr;
          stack[top++] = left_first ? Entry{right, tr} : Entry{left, tl};
          node = left_first ? left : right;
          continue;
        }
        if (hl || hr) {
          node = hl ? left : right;
          continue;
        }
      }
      // Pop the next subtree that can still hold a closer hit.
      bool found = false;
      while (top > 0) {
        const Entry e = stack[--top];
        if (e.t <= limit(t_max)) {
          node = e.node;
          found = true;
          break;
        }
      }
      if (!found) return;
    }
  }

 private:
  static float limit(double t_max) {
    return std::isfinite(t_max) ? static_cast<float>(t_max) * 1.0001f + kPad
                                : std::numeric_limits<float>::infinity();
  }

  struct Slabs {
    float inv[3], oinv[3];
    int near[3];  ///< which corner holds the near plane of each axis
  };

  static bool slab(const BvhNode& n, const Slabs& r, float t_lo, float t_hi, float& t_entry) {
    const float nx = n.box[r.near[0]][0] * r.inv[0] - r.oinv[0];
    const float ny = n.box[r.near[1]][1] * r.inv[1] - r.oinv[1];
    const float nz = n.box[r.near[2]][2] * r.inv[2] - r.oinv[2];
    const float fx = n.box[1 - r.near[0]][0] * r.inv[0] - r.oinv[0];
    const float fy = n.box[1 - r.near[1]][1] * r.inv[1] - r.oinv[1];
    const float fz = n.box[1 - r.near[2]][2] * r.inv[2] - r.oinv[2];
    const float tn = std::max(std::max(t_lo, nx), std::max(ny, nz));
    const float tf = std::min(std::min(t_hi, fx), std::min(fy, fz));
    t_entry = tn;
    return tn <= tf;
  }

  static Aabb bounds_of(const std::vector<Aabb>& boxes, const std::uint32_t* first,
                        const std::uint32_t* last) {
    Aabb b;
    for (const std::uint32_t* it = first; it != last; ++it) b.extend(boxes[*it]);
    return b;
  }

  std::uint32_t push_node(const Aabb& b) {
    BvhNode n{};
    for (int a = 0; a < 3; ++a) {
      n.box[0][a] =
          static_cast<float>(b.lo[a]) - kPad - 1e-6f * std::abs(static_cast<float>(b.lo[a]));
      n.box[1][a] =
          static_cast<float>(b.hi[a]) + kPad + 1e-6f * std::abs(static_cast<float>(b.hi[a]));
    }
    nodes_.push_back(n);
    return static_cast<std::uint32_t>(nodes_.size() - 1);
  }

  void make_leaf(std::uint32_t node, std::uint32_t begin, std::uint32_t end) {
    nodes_[node].index = begin;
    nodes_[node].count = end - begin;
  }

  void build_node(const std::vector<Aabb>& boxes, std::uint32_t begin, std::uint32_t end,
                  int depth) {
    std::uint32_t* items = items_.data();
    const std::uint32_t node = push_node(bounds_of(boxes, items + begin, items + end));
    const std::uint32_t count = end - begin;
    if (count <= kMaxLeaf) return make_leaf(node, begin, end);

    Aabb cb;  // centroid bounds choose the split axis
    for (std::uint32_t i = begin; i < end; ++i) cb.extend(centroids_[items[i]]);
    int axis = 0;
    const Vec3d extent = cb.hi - cb.lo;
    if (extent.y() > extent[axis]) axis = 1;
    if (extent.z() > extent[axis]) axis = 2;
    if (!(extent[axis] > 1e-12)) {  // all centroids coincide: split the list in halves
      const std::uint32_t mid = begin + count / 2;
      return finish_inner(boxes, node, begin, mid, end, depth);
    }

    std::uint32_t mid = begin;
    if (depth < kMedianDepth) {
      mid = sah_split(boxes, begin, end, axis, cb.lo[axis], extent[axis], node);
      if (mid == end) return make_leaf(node, begin, end);  // a leaf is cheaper
    }
    if (mid == begin || mid == end) {
      mid = begin + count / 2;
      std::nth_element(items + begin, items + mid, items + end,
                       [&](std::uint32_t a, std::uint32_t b) {
                         const double ca = centroids_[a][axis], cbv = centroids_[b][axis];
                         return ca < cbv || (ca == cbv && a < b);
                       });
    }
    finish_inner(boxes, node, begin, mid, end, depth);
  }

  void finish_inner(const std::vector<Aabb>& boxes, std::uint32_t node, std::uint32_t begin,
                    std::uint32_t mid, std::uint32_t end, int depth) {
    nodes_[node].count = 0;
    build_node(boxes, begin, mid, depth + 1);
    nodes_[node].index = static_cast<std::uint32_t>(nodes_.size());
    build_node(boxes, mid, end, depth + 1);
  }

  /// Partitions [begin, end) by the best binned SAH plane and returns the split point;
  /// returns `end` when keeping a leaf is cheaper, `begin` when no plane separates.
  std::uint32_t sah_split(const std::vector<Aabb>& boxes, std::uint32_t begin, std::uint32_t end,
                          int axis, double c_lo, double c_extent, std::uint32_t node) {
    std::uint32_t* items = items_.data();
    const double scale = kBins / c_extent;
    auto bin_of = [&](std::uint32_t item) {
      const int b = static_cast<int>((centroids_[item][axis] - c_lo) * scale);
      return std::clamp(b, 0, kBins - 1);
    };
    std::array<Aabb, kBins> bin_box{};
    std::array<std::uint32_t, kBins> bin_count{};
    for (std::uint32_t i = begin; i < end; ++i) {
      const int b = bin_of(items[i]);
      bin_box[b].extend(boxes[items[i]]);
      ++bin_count[b];
    }
    // Sweep: area and count on each side of the plane after bin k.
    std::array<double, kBins - 1> left_cost{};
    Aabb acc;
    std::uint32_t n = 0;
    for (int k = 0; k < kBins - 1; ++k) {
      acc.extend(bin_box[k]);
      n += bin_count[k];
      left_cost[k] = acc.half_area() * n;
    }
    double best = kInfinity;
    int best_k = -1;
    acc = Aabb{};
    n = 0;
    for (int k = kBins - 1; k > 0; --k) {
      acc.extend(bin_box[k]);
      n += bin_count[k];
      const double cost = left_cost[k - 1] + acc.half_area() * n;
      if (n > 0 && n < end - begin && cost < best) {
        best = cost;
        best_k = k - 1;
      }
    }
    if (best_k < 0) return begin;
    // Cost of one more node test plus the expected item tests below it, against testing
    // every item here.
    const double parent_area = std::max(nodes_area(node), 1e-12);
    const double split_cost = 1.0 + kItemCost * best / parent_area;
    if (split_cost >= kItemCost * static_cast<double>(end - begin) && end - begin <= 2 * kMaxLeaf)
      return end;
    const std::uint32_t* mid = std::partition(
        items + begin, items + end, [&](std::uint32_t item) { return bin_of(item) <= best_k; });
    return static_cast<std::uint32_t>(mid - items);
  }

  double nodes_area(std::uint32_t node) const {
    const BvhNode& n = nodes_[node];
    const double ex = n.box[1][0] - n.box[0][0], ey = n.box[1][1] - n.box[0][1],
                 ez = n.box[1][2] - n.box[0][2];
    return ex * ey + ey * ez + ez * ex;
  }

  std::vector<BvhNode> nodes_;
  std::vector<std::uint32_t> items_;
  std::vector<Vec3d> centroids_;  ///< build scratch
};

}  // namespace ulc::sim
