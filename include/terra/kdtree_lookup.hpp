// KdTreeLookup: the paper's way to find the nearest lattice point (a kd-tree over the lattice),
// kept to measure the O(1) cube-map lookup of lattice.hpp against it (bench_terra) and as a
// second, independent implementation for the tests. Same answers: ulc::KdTree uses
// ulc::squared_distance and breaks ties by the smaller index, as nearest() is defined in
// lattice_points.hpp.
#pragma once

#include <cstddef>
#include <vector>

#include "terra/lattice.hpp"
#include "terra/lattice_points.hpp"
#include "ulc/core/kdtree.hpp"
#include "ulc/core/types.hpp"

namespace terra {

class KdTreeLookup {
 public:
  explicit KdTreeLookup(const Lattice& lattice) : tree_(lattice.points()), lattice_(&lattice) {}

  std::size_t size() const { return tree_.size(); }
  const ulc::Vec3d& point(std::size_t i) const { return lattice_->point(i); }
  const std::vector<ulc::Vec3d>& points() const { return lattice_->points(); }

  LatticeIndex nearest(const ulc::Vec3d& q) const {
    std::size_t index = 0;
    double sq = 0;
    tree_.nearest(q, index, sq);
    return static_cast<LatticeIndex>(index);
  }

  void nearest_batch(const ulc::Vec3d* q, std::size_t n, LatticeIndex* out) const {
    for (std::size_t k = 0; k < n; ++k) out[k] = nearest(q[k]);
  }

 private:
  ulc::KdTree<std::vector<ulc::Vec3d>> tree_;
  const Lattice* lattice_;  ///< must outlive this lookup
};

}  // namespace terra
