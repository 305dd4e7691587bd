// KdTree<Cloud>: exact nearest-neighbour search over any traits cloud (nanoflann underneath).
//
// Conventions this header owns:
//   - The tree copies the cloud's points into its own contiguous array: it does not depend on
//     the cloud's lifetime, and later changes to the cloud are not seen.
//   - Indices are the cloud's own point indices. Points with a non-finite coordinate are not
//     indexed (they can be nobody's neighbour); skipped() counts them.
//   - Distances are squared Euclidean, in the cloud's scalar, computed as dx*dx + dy*dy + dz*dz
//     (squared_distance below). Results are sorted by (distance, index): equal distances are
//     broken by the smaller index, so answers are deterministic even with duplicate points.
//   - radius(q, r, ...) returns every point with squared distance <= r*r (a closed ball).
//   - A query point with a non-finite coordinate, k == 0, a negative or NaN radius, or an empty
//     tree give no neighbours. Nothing here throws, prints or allocates per kNN query.
//   - Const queries are safe from many threads at once (the result sets live in the call).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include "ulc/core/cloud.hpp"
#include "ulc/core/nanoflann_compat.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

/// The one distance every search (and every brute-force check of it) uses.
template <typename S>
S squared_distance(const Vec3<S>& a, const Vec3<S>& b) {
  const S dx = a.x() - b.x();
  const S dy = a.y() - b.y();
  const S dz = a.z() - b.z();
  return dx * dx + dy * dy + dz * dz;
}

template <typename S>
bool is_finite_point(const Vec3<S>& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

namespace detail {

/// What nanoflann reads: the copied points, in tree order.
template <typename S>
struct KdTreePoints {
  std::vector<Vec3<S>> points;

  std::size_t kdtree_get_point_count() const { return points.size(); }
  S kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return points[i][static_cast<Eigen::Index>(dim)];
  }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;  // let nanoflann compute it (never called on an empty set, see KdTree)
  }
};

/// Squared L2 with our exact arithmetic (the same expression as squared_distance).
template <typename S>
struct KdTreeMetric {
  using ElementType = S;
  using DistanceType = S;

  explicit KdTreeMetric(const KdTreePoints<S>& data) : data_(data) {}

  template <typename Index>
  S evalMetric(const S* a, Index b, std::size_t /*dim*/) const {
    const Vec3<S>& p = data_.points[static_cast<std::size_t>(b)];
    const S dx = a[0] - p.x();
    const S dy = a[1] - p.y();
    const S dz = a[2] - p.z();
    return dx * dx + dy * dy + dz * dz;
  }
  template <typename U, typename V>
  S accum_dist(U a, V b, std::size_t) const {
    const S d = static_cast<S>(a - b);
    return d * d;
  }

 private:
  const KdTreePoints<S>& data_;
};

}  // namespace detail

template <class Cloud>
class KdTree {
 public:
  using Scalar = traits::scalar_t<Cloud>;
  using Point = Vec3<Scalar>;
  static constexpr std::size_t kDefaultLeafSize = 10;

  /// An empty tree: every query returns no neighbours.
  KdTree() : data_(std::make_unique<detail::KdTreePoints<Scalar>>()) {}

  explicit KdTree(const Cloud& cloud, std::size_t leaf_size = kDefaultLeafSize)
      : data_(std::make_unique<detail::KdTreePoints<Scalar>>()) {
    const std::size_t n = traits::size(cloud);
    data_->points.reserve(n);
    original_index_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Point p = traits::point(cloud, i);
      if (!is_finite_point(p)) continue;
      data_->points.push_back(p);
      original_index_.push_back(i);
    }
    skipped_ = n - data_->points.size();
    if (skipped_ == 0) std::vector<std::size_t>().swap(original_index_);  // identity: no map
    if (data_->points.empty()) return;  // nanoflann must never build or search an empty set
    index_ = std::make_unique<Index>(3, *data_, nanoflann_compat::index_params(leaf_size));
  }

  // The index refers to data_ by address; both live on the heap, so moving is safe.
  KdTree(KdTree&&) noexcept = default;
  KdTree& operator=(KdTree&&) noexcept = default;
  KdTree(const KdTree&) = delete;
  KdTree& operator=(const KdTree&) = delete;

  /// Number of indexed (finite) points.
  std::size_t size() const { return data_ ? data_->points.size() : 0; }
  bool empty() const { return size() == 0; }
  /// Points of the cloud left out because a coordinate was NaN or infinite.
  std::size_t skipped() const { return skipped_; }

  /// The k nearest points, sorted by (squared distance, index), into caller arrays of at least
  /// k entries. Returns how many were found: min(k, size()).
  std::size_t knn(const Point& query, std::size_t k, std::size_t* indices, Scalar* sq_dists) const {
    if (!index_ || k == 0 || !is_finite_point(query)) return 0;
    nanoflann_compat::KnnResultSet<Scalar> result(k, indices, sq_dists);
    result.init();
    index_->findNeighbors(result, query.data(), nanoflann_compat::SearchParamsT());
    to_cloud_indices(indices, result.size());
    return result.size();
  }

  /// Same, into vectors resized to the number found.
  std::size_t knn(const Point& query, std::size_t k, std::vector<std::size_t>& indices,
                  std::vector<Scalar>& sq_dists) const {
    const std::size_t capacity = std::min(k, size());
    indices.resize(capacity);
    sq_dists.resize(capacity);
    const std::size_t found = knn(query, capacity, indices.data(), sq_dists.data());
    indices.resize(found);
    sq_dists.resize(found);
    return found;
  }

  /// The nearest point; false when there is none.
  bool nearest(const Point& query, std::size_t& index, Scalar& sq_dist) const {
    return knn(query, 1, &index, &sq_dist) == 1;
  }

  /// Every point within distance r (squared distance <= r^2), sorted by (distance, index).
  std::size_t radius(const Point& query, Scalar r, std::vector<std::size_t>& indices,
                     std::vector<Scalar>& sq_dists) const {
    indices.clear();
    sq_dists.clear();
    if (!index_ || !(r >= Scalar(0)) || !is_finite_point(query)) return 0;
    std::vector<typename nanoflann_compat::RadiusResultSet<Scalar>::Item> items;
    nanoflann_compat::RadiusResultSet<Scalar> result(r * r, items);
    result.init();
    index_->findNeighbors(result, query.data(), nanoflann_compat::SearchParamsT());
    std::sort(items.begin(), items.end());  // pairs (distance, index): the order we promise
    indices.reserve(items.size());
    sq_dists.reserve(items.size());
    for (const auto& item : items) {
      sq_dists.push_back(item.first);
      indices.push_back(item.second);
    }
    to_cloud_indices(indices.data(), indices.size());
    return indices.size();
  }

 private:
  using Index = nanoflann::KDTreeSingleIndexAdaptor<detail::KdTreeMetric<Scalar>,
                                                    detail::KdTreePoints<Scalar>, 3, std::size_t>;

  // Tree order is cloud order minus the skipped points, so the map is increasing and sorting
  // by tree index equals sorting by cloud index.
  void to_cloud_indices(std::size_t* indices, std::size_t n) const {
    if (original_index_.empty()) return;
    for (std::size_t i = 0; i < n; ++i) indices[i] = original_index_[indices[i]];
  }

  std::unique_ptr<detail::KdTreePoints<Scalar>> data_;
  std::unique_ptr<Index> index_;
  std::vector<std::size_t> original_index_;  ///< tree index -> cloud index; empty: identity
  std::size_t skipped_ = 0;
};

}  // namespace ulc
