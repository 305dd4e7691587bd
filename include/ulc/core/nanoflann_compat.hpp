// The one place ULC includes nanoflann, and the small adapters that make one KdTree work with
// nanoflann 1.4.x (Debian 12: NANOFLANN_VERSION 0x142) and 1.5+ alike.
//
// What differs between the versions, and how it is absorbed here:
//   - 1.5 renamed SearchParams -> SearchParameters (and dropped the unused `checks` field):
//     `SearchParamsT` picks the right one by NANOFLANN_VERSION; we only default-construct it.
//   - 1.5 renamed the radius result item (std::pair -> ResultItem) and gave
//     KDTreeSingleIndexAdaptorParams an `n_thread_build` field: we use our own result sets
//     (below), so no nanoflann result type appears in our code, and we ask for a one-thread build
//     when the field exists (nanoflann builds with std::async otherwise, outside TBB's control).
//   - Members of the index were renamed (root_node -> root_node_, ...): we never touch them.
//
// -fno-exceptions: nanoflann has `throw` in non-template code, which g++ rejects even when it is
// never reached. Without exceptions we include it with `throw` defined away (every throw becomes
// a discarded expression), after pre-including the standard headers it uses so the macro only
// ever sees nanoflann's own text. KdTree guarantees nanoflann's throwing conditions never arise
// (no empty build, no search before build); only an out-of-memory in its pool allocator, which
// no caller could handle anyway, is left unguarded.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <future>
#include <istream>
#include <limits>
#include <mutex>
#include <ostream>
#include <stdexcept>
#include <thread>
#include <type_traits>
#include <unordered_set>
#include <utility>
#include <vector>

#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
#include <nanoflann.hpp>
#else
#if defined(__clang__)
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wkeyword-macro"  // redefining `throw` is the point here
#endif
#define throw (void)
#include <nanoflann.hpp>
#undef throw
#if defined(__clang__)
#pragma clang diagnostic pop
#endif
#endif

namespace ulc {
namespace nanoflann_compat {

#if NANOFLANN_VERSION >= 0x150
using SearchParamsT = nanoflann::SearchParameters;
#else
using SearchParamsT = nanoflann::SearchParams;
#endif

template <typename T, typename = void>
struct has_n_thread_build : std::false_type {};
template <typename T>
struct has_n_thread_build<T, std::void_t<decltype(std::declval<T&>().n_thread_build)>>
    : std::true_type {};

/// Sets a single-threaded build where the version can do more (a template, so that the
/// discarded branch is not compiled against 1.4, which lacks the field).
template <typename Params>
void request_serial_build(Params& params) {
  if constexpr (has_n_thread_build<Params>::value) params.n_thread_build = 1;
}

/// Index parameters: the leaf size and a serial build.
inline nanoflann::KDTreeSingleIndexAdaptorParams index_params(std::size_t leaf_max_size) {
  nanoflann::KDTreeSingleIndexAdaptorParams params(leaf_max_size);
  request_serial_build(params);
  return params;
}

/// Strict order used by every search: by squared distance, ties by the smaller index. Makes
/// the answer independent of the tree's traversal order (duplicates, regular grids).
template <typename S>
bool closer(S d1, std::size_t i1, S d2, std::size_t i2) {
  return d1 < d2 || (d1 == d2 && i1 < i2);
}

/// nanoflann only offers a point to a result set when `dist < worstDist()`, and prunes a branch
/// when its bound exceeds worstDist(). Reporting the next representable value above the current
/// worst lets points *equal* to the worst through, so ties can be decided by index.
template <typename S>
S just_above(S d) {
  return std::nextafter(d, std::numeric_limits<S>::infinity());
}

/// The k nearest, kept sorted by (distance, index) in caller-owned arrays of capacity k.
/// Implements what nanoflann's findNeighbors calls: init/size/full/addPoint/worstDist.
template <typename S>
class KnnResultSet {
 public:
  using DistanceType = S;
  using IndexType = std::size_t;
  using CountType = std::size_t;

  KnnResultSet(std::size_t capacity, std::size_t* indices, S* sq_dists)
      : capacity_(capacity), indices_(indices), dists_(sq_dists) {}

  void init() {
    count_ = 0;
    worst_ = std::numeric_limits<S>::infinity();
  }
  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }
  bool full() const { return count_ == capacity_; }

  bool addPoint(S dist, std::size_t index) {
    if (full() && !closer(dist, index, dists_[count_ - 1], indices_[count_ - 1])) return true;
    std::size_t i = full() ? count_ - 1 : count_++;
    // Insertion step: shift every entry farther than the new one by one place.
    for (; i > 0 && closer(dist, index, dists_[i - 1], indices_[i - 1]); --i) {
      dists_[i] = dists_[i - 1];
      indices_[i] = indices_[i - 1];
    }
    dists_[i] = dist;
    indices_[i] = index;
    if (full()) worst_ = just_above(dists_[count_ - 1]);
    return true;  // keep searching
  }

  /// Kept up to date by addPoint: nanoflann asks for it at every node it visits.
  S worstDist() const { return worst_; }

 private:
  std::size_t capacity_;
  std::size_t count_ = 0;
  std::size_t* indices_;
  S* dists_;
  S worst_ = std::numeric_limits<S>::infinity();
};

/// Every point with squared distance <= radius^2 (closed ball), unsorted; the caller sorts.
template <typename S>
class RadiusResultSet {
 public:
  using DistanceType = S;
  using IndexType = std::size_t;
  using CountType = std::size_t;
  using Item = std::pair<S, std::size_t>;  ///< (squared distance, index)

  RadiusResultSet(S sq_radius, std::vector<Item>& out)
      : sq_radius_(sq_radius), bound_(just_above(sq_radius)), out_(out) {}

  void init() { out_.clear(); }
  std::size_t size() const { return out_.size(); }
  bool empty() const { return out_.empty(); }
  bool full() const { return true; }  // a radius search never stops early

  bool addPoint(S dist, std::size_t index) {
    if (dist <= sq_radius_) out_.emplace_back(dist, index);
    return true;
  }
  S worstDist() const { return bound_; }

 private:
  S sq_radius_;
  S bound_;
  std::vector<Item>& out_;
};

}  // namespace nanoflann_compat
}  // namespace ulc
