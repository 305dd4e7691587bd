// Rotating a TERRA descriptor by re-indexing its cells (the paper's "Rotation of the TERRA").
//
// Conventions this header owns:
//   - rotate(F, R) is the descriptor of the cloud turned by R (every point p becomes R p):
//       G[j] = F[nearest(R^T l_j)]                                    (pull form)
//     A point seen along direction d is seen along R d afterwards, so the cell at l_j now shows
//     what F showed along R^T l_j.
//   - Why this is the paper's operation. The paper rotates the lattice (l_i -> R l_i), pairs each
//     rotated point with its nearest original point and moves the values along the pairs (push
//     form). R is an isometry, so |R l_i - l_j| = |l_i - R^T l_j|: the source i nearest to the
//     rotated position of cell j is exactly nearest(R^T l_j). Pulling asks that question once
//     per destination cell j, so every cell receives exactly one value: no two values collide in
//     one cell and no cell is left without one, which the push form cannot promise.
//   - A RotationIndexMap is that pairing for one rotation: source[j] = nearest(R^T l_j). Build it
//     once, apply it to any number of descriptors on the same lattice.
//   - Deterministic: every entry is computed on its own (parallel over cells).
#pragma once

#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "terra/descriptor.hpp"
#include "terra/lattice.hpp"
#include "ulc/core/types.hpp"

namespace terra {

struct RotationIndexMap {
  std::vector<LatticeIndex> source;  ///< rotated[j] = original[source[j]]
  std::size_t size() const { return source.size(); }
};

/// The map of rotation R on `lookup` (Lattice or KdTreeLookup).
template <class Lookup>
RotationIndexMap rotation_index_map(const Lookup& lookup, const ulc::Mat3d& R) {
  RotationIndexMap map;
  const std::size_t n = lookup.size();
  map.source.resize(n);
  const ulc::Mat3d Rt = R.transpose();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t j = r.begin(); j < r.end(); ++j)
                        map.source[j] = lookup.nearest(Rt * lookup.point(j));
                    });
  return map;
}

/// G[j] = F[map.source[j]]; the point counts are carried over. Sizes must match.
template <typename S>
Descriptor<S> rotate(const Descriptor<S>& f, const RotationIndexMap& map) {
  Descriptor<S> g;
  g.points_used = f.points_used;
  g.points_ignored = f.points_ignored;
  g.points_invalid = f.points_invalid;
  if (map.size() != f.size()) return g;  // mismatched lattices: nothing meaningful to return
  g.range.resize(f.size());
  for (std::size_t j = 0; j < f.size(); ++j) g.range[j] = f.range[map.source[j]];
  return g;
}

/// rotate(F, R) in one call.
template <class Lookup, typename S>
Descriptor<S> rotate(const Lookup& lookup, const Descriptor<S>& f, const ulc::Mat3d& R) {
  return rotate(f, rotation_index_map(lookup, R));
}

}  // namespace terra
