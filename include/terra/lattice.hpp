// Lattice: the paper's Fibonacci lattice (Algorithm 1) with an O(1) exact nearest-point lookup.
//
// The paper finds nearest lattice points with a kd-tree (O(log N) per query; kdtree_lookup.hpp
// keeps that method for comparison). Here a cube-map table answers in O(1):
//   - the sphere is cut into 6 x M x M cube-map cells (cube_map.hpp), each several times smaller
//     than the lattice spacing;
//   - each cell stores every lattice point that can be the nearest one to some direction inside
//     the cell (1.96 on average at the default size; up to 4 inline in the cell's own 16-byte
//     record, more in a rare overflow list);
//   - a query finds its cell and compares the exact distances to its candidates. The answer is
//     therefore exactly nearest(q) of lattice_points.hpp.
// Cost model (bench_terra): the search's queries jump around the sphere, so a lookup is bound by
// memory latency and branch mispredictions, not arithmetic. Hence one record per cell (one cache
// line read, then the candidate points), a branch-free comparison of all 4 slots, a face
// selection without branches (cube_map.hpp), and nearest_batch, which prefetches a chunk's
// records and points before using any: 21 ns per lookup against 30 one by one and ~300 for the
// kd-tree, measured on this project's 2-core build machine.
//
// Why the candidate list is complete. Let c be the cell centre, r the largest angle from c to a
// corner, p any lattice point and b the largest angle from p to a corner. The cell is convex and
// within 90 degrees of c and of p, so no direction d of the cell is farther than r from c or b
// from p. The nearest lattice point l to d satisfies angle(d, l) <= angle(d, p) <= b, hence
// angle(c, l) <= r + b. The table stores every lattice point within r + b (+ a rounding margin)
// of c. p only has to be close to c for the list to be short, not to be the nearest: it is found
// by a greedy walk over the lattice's k-nearest-neighbour graph.
//
// Conventions: see lattice_points.hpp (point order, the nearest() definition, ties by index).
// Queries must be finite, non-zero, and should be unit length (the nearest point is the one
// nearest to q itself). Construction is O(N log N + M^2) and parallel (TBB), with the same table
// for any thread count (each cell is computed on its own).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "terra/cube_map.hpp"
#include "terra/lattice_points.hpp"
#include "ulc/core/kdtree.hpp"
#include "ulc/core/types.hpp"

namespace terra {

struct LatticeOptions {
  /// Cube-map cell size: the angle from a face-centre cell's centre to its corner, as a
  /// fraction of the lattice spacing (lattice_spacing_rad). Smaller: more single-candidate
  /// cells (fewer distance checks per query), bigger table. At N = 10000, 0.25 gives a 1.9 MB
  /// table, 1.96 candidates per cell on average and lookups as fast as 0.125 (5 MB, memory
  /// bound) while building 3x faster; bench_terra measures the choice.
  double cell_fraction = 0.25;
  /// Upper bound on M, so a huge N cannot ask for a huge table; the lookup stays exact (cells
  /// just hold more candidates).
  std::size_t max_cells_per_edge = 1024;
};

class Lattice {
 public:
  /// An empty lattice (size() == 0): nothing may be looked up.
  Lattice() = default;

  /// Algorithm 1 with n points (n >= 2; fewer gives an empty lattice) and its lookup table.
  explicit Lattice(std::size_t n, const LatticeOptions& options = {})
      : points_(fibonacci_lattice(n)) {
    if (points_.size() < 2 || points_.size() >= kOverflow) {
      points_.clear();
      return;
    }
    const double spacing = lattice_spacing_rad(points_.size());
    const double fraction = options.cell_fraction > 0 ? options.cell_fraction : 0.25;
    // A face-centre cell of M per edge spans 2/M in u and v: centre-to-corner angle ~ sqrt2/M.
    const double m = std::ceil(std::sqrt(2.0) / (fraction * spacing));
    grid_ = CubeMapGrid(static_cast<std::size_t>(
        std::min(std::max(m, 1.0),
                 static_cast<double>(std::max<std::size_t>(options.max_cells_per_edge, 1)))));
    build_table();
  }

  std::size_t size() const { return points_.size(); }
  bool empty() const { return points_.empty(); }
  const ulc::Vec3d& point(std::size_t i) const { return points_[i]; }
  const std::vector<ulc::Vec3d>& points() const { return points_; }
  const CubeMapGrid& grid() const { return grid_; }

  /// nearest(q) of lattice_points.hpp, in O(1). q: finite, non-zero, unit length.
  LatticeIndex nearest(const ulc::Vec3d& q) const {
    return nearest_in(slots_.data() + kSlots * grid_.cell_of(q), q);
  }

  /// nearest() of n queries at once, into out[0..n). Same answers, faster for scattered
  /// queries: the reads of a whole chunk are issued (prefetched) before any is used, so their
  /// memory latencies overlap instead of adding up (a query's own reads depend on one another:
  /// cell record, then candidate points).
  void nearest_batch(const ulc::Vec3d* q, std::size_t n, LatticeIndex* out) const {
    constexpr std::size_t kChunk = 32;
    const std::uint32_t* record[kChunk];
    for (std::size_t begin = 0; begin < n; begin += kChunk) {
      const std::size_t m = std::min(kChunk, n - begin);
      const ulc::Vec3d* qc = q + begin;
      for (std::size_t k = 0; k < m; ++k) {
        record[k] = slots_.data() + kSlots * grid_.cell_of(qc[k]);
        prefetch(record[k]);
      }
      for (std::size_t k = 0; k < m; ++k) {
        if (record[k][0] & kOverflow) continue;
        for (std::size_t c = 0; c < kSlots; ++c) prefetch(points_.data() + record[k][c]);
      }
      for (std::size_t k = 0; k < m; ++k) out[begin + k] = nearest_in(record[k], qc[k]);
    }
  }

  /// Candidates stored for a cube-map cell (1 = the table alone answers).
  std::size_t candidate_count(std::size_t cell) const {
    const std::uint32_t* r = slots_.data() + kSlots * cell;
    if (r[0] & kOverflow) return extra_[r[0] & ~kOverflow];
    std::size_t count = 1;
    for (std::size_t c = 1; c < kSlots; ++c) count += r[c] != r[0];
    return count;
  }
  /// Mean of candidate_count over all cells.
  double mean_candidates() const {
    std::size_t total = 0;
    for (std::size_t cell = 0; cell < grid_.cell_count(); ++cell) total += candidate_count(cell);
    return empty() ? 0.0 : static_cast<double>(total) / static_cast<double>(grid_.cell_count());
  }
  std::size_t table_bytes() const {
    return (slots_.size() + extra_.size()) * sizeof(std::uint32_t);
  }

 private:
  /// Candidates stored in a cell's own record. Unused slots repeat the first candidate (which
  /// never wins a comparison against itself), so a lookup always compares kSlots points
  /// without a data-dependent branch. Cells with more candidates (0.01% at the default cell
  /// size) set kOverflow in slot 0, the rest being an offset into extra_: [count, i1, i2, ...].
  static constexpr std::size_t kSlots = 4;
  static constexpr std::uint32_t kOverflow = 0x80000000u;
  static constexpr std::size_t kGraphNeighbours = 12;
  static constexpr double kMarginRad = 1e-9;  ///< far above double rounding, far below spacing
  static constexpr double kHalfPi = 1.57079632679489661923;

  template <typename T>
  static void prefetch(const T* p) {
#if defined(__GNUC__) || defined(__clang__)
    __builtin_prefetch(p);
#else
    (void)p;
#endif
  }

  /// The nearest among a cell's candidates. Candidates are sorted by index and compared with a
  /// strict <, so equal distances keep the smaller index.
  LatticeIndex nearest_in(const std::uint32_t* record, const ulc::Vec3d& q) const {
    if (record[0] & kOverflow) {
      const std::uint32_t* list = extra_.data() + (record[0] & ~kOverflow);
      return nearest_among(list + 1, list[0], q);
    }
    return nearest_among(record, kSlots, q);
  }
  LatticeIndex nearest_among(const std::uint32_t* candidates, std::size_t count,
                             const ulc::Vec3d& q) const {
    LatticeIndex best = candidates[0];
    double best_d = ulc::squared_distance(q, points_[best]);
    for (std::size_t k = 1; k < count; ++k) {
      const double d = ulc::squared_distance(q, points_[candidates[k]]);
      const bool closer = d < best_d;
      best = closer ? candidates[k] : best;
      best_d = closer ? d : best_d;
    }
    return best;
  }

  // Chord length <-> angle on the unit sphere.
  static double chord_to_angle(double sq_chord) {
    return 2.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(sq_chord)));
  }

  void build_table() {
    using Cloud = std::vector<ulc::Vec3d>;
    const ulc::KdTree<Cloud> tree(points_);
    const std::size_t n = points_.size();
    const std::size_t k = std::min(kGraphNeighbours + 1, n);  // + the point itself
    // k-nearest-neighbour graph: neighbours[i * (k - 1) ...], and the angle to the farthest.
    std::vector<LatticeIndex> neighbours(n * (k - 1));
    std::vector<double> reach(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        std::vector<std::size_t> idx(k);
                        std::vector<double> sq(k);
                        for (std::size_t i = range.begin(); i < range.end(); ++i) {
                          tree.knn(points_[i], k, idx.data(), sq.data());
                          std::size_t out = 0;
                          for (std::size_t j = 0; j < k && out < k - 1; ++j)
                            if (idx[j] != i)
                              neighbours[i * (k - 1) + out++] = static_cast<LatticeIndex>(idx[j]);
                          // Every point within `reach` of point i is i or one of its neighbours.
                          reach[i] = k == n ? 4.0 : chord_to_angle(sq[k - 1]);
                        }
                      });

    // One row of cells at a time; rows are joined in order, so the table is thread-independent.
    const std::size_t m = grid_.cells_per_edge();
    const std::size_t rows = 6 * m;
    slots_.assign(kSlots * grid_.cell_count(), 0);
    std::vector<std::vector<std::uint32_t>> row_extra(rows);
    const std::size_t degree = k - 1;
    auto walk = [&](LatticeIndex p, const ulc::Vec3d& c) {
      double d = ulc::squared_distance(c, points_[p]);
      for (;;) {  // strictly decreasing distance: terminates
        LatticeIndex best = p;
        for (std::size_t j = 0; j < degree; ++j) {
          const LatticeIndex q = neighbours[p * degree + j];
          const double dq = ulc::squared_distance(c, points_[q]);
          if (dq < d) {
            d = dq;
            best = q;
          }
        }
        if (best == p) return p;
        p = best;
      }
    };
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, rows, 4),
        [&](const tbb::blocked_range<std::size_t>& range) {
          std::vector<std::size_t> idx;
          std::vector<double> sq;
          std::vector<LatticeIndex> candidates;
          for (std::size_t row = range.begin(); row < range.end(); ++row) {
            std::size_t start = 0;
            double start_sq = 0;
            tree.nearest(grid_.centre(row * m), start, start_sq);
            LatticeIndex p = static_cast<LatticeIndex>(start);
            for (std::size_t cell = row * m; cell < (row + 1) * m; ++cell) {
              const ulc::Vec3d c = grid_.centre(cell);
              const auto corners = grid_.corners(cell);
              p = walk(p, c);
              double r = 0, b = 0;
              for (const ulc::Vec3d& corner : corners) {
                r = std::max(r, angle_between(c, corner));
                b = std::max(b, angle_between(points_[p], corner));
              }
              const double rho = r + b + kMarginRad;
              candidates.clear();
              if (b >= kHalfPi) {  // a cell as big as a hemisphere (tiny N): keep everything
                for (std::size_t i = 0; i < n; ++i)
                  candidates.push_back(static_cast<LatticeIndex>(i));
              } else if (reach[p] > rho + angle_between(c, points_[p]) + kMarginRad) {
                // Every lattice point within rho of c is within reach of p: p or a neighbour.
                if (angle_between(c, points_[p]) <= rho) candidates.push_back(p);
                for (std::size_t j = 0; j < degree; ++j) {
                  const LatticeIndex q = neighbours[p * degree + j];
                  if (angle_between(c, points_[q]) <= rho) candidates.push_back(q);
                }
              } else {
                const double chord = 2.0 * std::sin(0.5 * std::min(rho, 2.0 * kHalfPi));
                tree.radius(c, chord * (1.0 + 1e-9), idx, sq);
                for (const std::size_t q : idx)
                  if (angle_between(c, points_[q]) <= rho)
                    candidates.push_back(static_cast<LatticeIndex>(q));
              }
              std::sort(candidates.begin(), candidates.end());
              std::uint32_t* record = slots_.data() + kSlots * cell;
              if (candidates.size() <= kSlots) {
                for (std::size_t slot = 0; slot < kSlots; ++slot)
                  record[slot] = candidates[slot < candidates.size() ? slot : 0];
              } else {
                // Local offset within the row for now; made global after the rows are joined.
                auto& extra = row_extra[row];
                record[0] = kOverflow | static_cast<std::uint32_t>(extra.size());
                extra.push_back(static_cast<std::uint32_t>(candidates.size()));
                extra.insert(extra.end(), candidates.begin(), candidates.end());
              }
            }
          }
        });
    for (std::size_t row = 0; row < rows; ++row) {
      const auto base = static_cast<std::uint32_t>(extra_.size());
      for (std::size_t cell = row * m; cell < (row + 1) * m; ++cell)
        if (slots_[kSlots * cell] & kOverflow) slots_[kSlots * cell] += base;
      extra_.insert(extra_.end(), row_extra[row].begin(), row_extra[row].end());
    }
  }

  std::vector<ulc::Vec3d> points_;
  CubeMapGrid grid_;
  std::vector<std::uint32_t> slots_;  ///< kSlots per cube-map cell
  std::vector<std::uint32_t> extra_;  ///< candidate lists of overflowing cells
};

}  // namespace terra
