// PlaneCloud: a registration target (registration_types.hpp) made from any traits cloud: a
// kd-tree over its points and one plane per point.
//
// Conventions this header owns:
//   - Planes come from the cloud's own normals when it carries them (and use_cloud_normals),
//     otherwise from PCA over the k nearest neighbours (normals.hpp), keeping only points whose
//     planarity is at least min_planarity.
//   - Only points with a usable plane are indexed: a query's match is the nearest such point
//     within the gate (ties: the lower index), and the residual is measured to its plane.
//   - The search is bounded by the gate from its start (NearestWithin below), so a query with
//     nothing near costs a few tree levels instead of a full nearest-neighbour search. (A
//     KdTree::nearest with a distance bound in kdtree.hpp would be its natural home.)
//   - The PlaneCloud copies what it needs; the cloud may go away after construction.
#pragma once

#include <cmath>
#include <cstddef>
#include <memory>
#include <vector>

#include "ulc/core/cloud.hpp"
#include "ulc/core/kdtree.hpp"
#include "ulc/core/nanoflann_compat.hpp"
#include "ulc/core/normals.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/registration_types.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

namespace detail {

/// nanoflann result set: the nearest point with squared distance <= a bound (ties: lower
/// index). Reporting the bound as the worst distance from the start prunes every branch beyond.
template <typename S>
class NearestWithin {
 public:
  using DistanceType = S;
  using IndexType = std::size_t;
  using CountType = std::size_t;

  explicit NearestWithin(S sq_bound)
      : best_(sq_bound), worst_(nanoflann_compat::just_above(sq_bound)) {}
  void init() {}
  std::size_t size() const { return found_ ? 1 : 0; }
  bool full() const { return true; }
  bool addPoint(S dist, std::size_t index) {
    if (dist < best_ || (dist == best_ && (!found_ || index < index_))) {
      best_ = dist;
      worst_ = nanoflann_compat::just_above(dist);
      index_ = index;
      found_ = true;
    }
    return true;
  }
  /// Kept up to date by addPoint: nanoflann asks for it at every node it visits.
  S worstDist() const { return worst_; }

  bool found() const { return found_; }
  std::size_t index() const { return index_; }

 private:
  S best_;
  S worst_;  ///< just above best_
  std::size_t index_ = 0;
  bool found_ = false;
};

}  // namespace detail

template <typename S>
class PlaneCloud {
 public:
  using Points = std::vector<Vec3<S>>;

  PlaneCloud() = default;

  template <class Cloud>
  explicit PlaneCloud(const Cloud& cloud, const PlaneCloudOptions& options = {}) {
    const std::size_t n = traits::size(cloud);
    if (options.use_cloud_normals && traits::has_normal(cloud)) {
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3<S> p = traits::point(cloud, i).template cast<S>();
        Vec3<S> nrm = traits::normal(cloud, i).template cast<S>();
        const S len = nrm.norm();
        if (!is_finite_point(p) || !(len > S(0)) || !std::isfinite(len)) continue;
        points_.push_back(p);
        normals_.push_back(nrm / len);
      }
    } else {
      Points all;
      all.reserve(n);
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3<S> p = traits::point(cloud, i).template cast<S>();
        if (is_finite_point(p)) all.push_back(p);
      }
      const KdTree<Points> all_tree(all);
      NormalEstimationOptions normal_options;
      normal_options.k = options.normal_k;
      const auto normals = estimate_normals(all, all_tree, normal_options);
      if (normals.ok()) {
        for (std::size_t i = 0; i < all.size(); ++i) {
          const auto& pn = normals.points[i];
          if (!pn.valid || pn.planarity < S(options.min_planarity)) continue;
          points_.push_back(all[i]);
          normals_.push_back(pn.normal);
        }
      }
    }
    if (points_.empty()) return;
    data_ = std::make_unique<ulc::detail::KdTreePoints<S>>();
    data_->points = points_;
    index_ = std::make_unique<Index>(3, *data_, nanoflann_compat::index_params(10));
  }

  /// Points with a usable plane, and their unit normals.
  const Points& points() const { return points_; }
  const Points& normals() const { return normals_; }
  std::size_t size() const { return points_.size(); }
  bool empty() const { return points_.empty(); }

  bool find_plane(const Vec3d& query, double max_distance, PlaneMatch& out) const {
    if (!index_ || !(max_distance >= 0.0) || !is_finite_point(query)) return false;
    const Vec3<S> q = query.cast<S>();
    detail::NearestWithin<S> result(static_cast<S>(max_distance * max_distance));
    index_->findNeighbors(result, q.data(), nanoflann_compat::SearchParamsT());
    if (!result.found()) return false;
    out.point = points_[result.index()].template cast<double>();
    out.normal = normals_[result.index()].template cast<double>();
    return true;
  }

 private:
  using Index = nanoflann::KDTreeSingleIndexAdaptor<ulc::detail::KdTreeMetric<S>,
                                                    ulc::detail::KdTreePoints<S>, 3, std::size_t>;
  Points points_;
  Points normals_;
  std::unique_ptr<ulc::detail::KdTreePoints<S>> data_;  ///< what the index reads (stable address)
  std::unique_ptr<Index> index_;
};

}  // namespace ulc
