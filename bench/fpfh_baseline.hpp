// A global-registration baseline for the rotation initialisation: FPFH features (Rusu, Blodow
// and Beetz, ICRA 2009) matched between the two frames, then RANSAC over the matches, as Open3D's
// registration_ransac_based_on_feature_matching does and as the paper's "FPFH with TEASER++"
// baseline starts. Written for bench_terra only (the library has no FPFH; PCL and Open3D are not
// dependencies), with Open3D's tutorial settings scaled to a 1 m voxel:
//   - both frames voxel-downsampled (voxel), normals from the 10 nearest points, turned towards
//     the sensor;
//   - SPFH over the neighbours within feature_radius (5 voxels; at most max_neighbours nearest):
//     the Darboux-frame angles (alpha, phi, theta) in 11 bins each, every sub-histogram scaled
//     to sum 100; FPFH(p) = SPFH(p) + mean over neighbours q of SPFH(q) / |p - q|;
//   - each target feature matched to its nearest base feature (L2), kept when mutual;
//   - RANSAC: 3 matches per draw, an edge-length check (each side within 10 %), the rigid
//     transform of the three (Eigen::umeyama), scored by the matches within inlier_distance; the
//     best transform refitted on its inliers. Seeded: the same answer for the same input.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "terra/random_rotation.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/kdtree.hpp"
#include "ulc/core/normals.hpp"
#include "ulc/core/voxel_downsample.hpp"

namespace fpfh_baseline {

using ulc::Mat3d;
using ulc::Vec3d;

struct Options {
  double voxel = 1.0;                ///< m
  double feature_radius = 5.0;       ///< m
  std::size_t max_neighbours = 100;  ///< of the feature's radius search
  int iterations = 20000;            ///< RANSAC draws
  double inlier_distance = 1.5;      ///< m (1.5 voxels, Open3D's tutorial)
  double edge_tolerance = 0.1;       ///< relative, the edge-length check
  std::uint64_t seed = 1;
};

constexpr int kBins = 11;
using Feature = std::array<float, 3 * kBins>;

/// A frame reduced to what the baseline matches: points, normals and their features.
struct Described {
  std::vector<Vec3d> points;
  std::vector<Vec3d> normals;
  std::vector<Feature> features;
};

struct Result {
  bool ok = false;
  Mat3d rotation = Mat3d::Identity();  ///< R_base_target
  Vec3d translation = Vec3d::Zero();
  std::size_t matches = 0, inliers = 0;
};

namespace detail {

inline int bin(double value, double lo, double hi) {
  const int b = static_cast<int>(std::floor((value - lo) / (hi - lo) * kBins));
  return std::clamp(b, 0, kBins - 1);
}

/// The simplified point feature histogram of point i over its neighbours.
inline Feature spfh(const Described& d, std::size_t i, const std::vector<std::size_t>& near) {
  Feature h{};
  std::size_t used = 0;
  for (std::size_t j : near) {
    if (j == i) continue;
    const Vec3d delta = d.points[j] - d.points[i];
    const double dist = delta.norm();
    if (!(dist > 0.0)) continue;
    const Vec3d u = d.normals[i], step = delta / dist;
    const Vec3d v = u.cross(step);
    if (v.norm() < 1e-9) continue;
    const Vec3d vn = v.normalized(), w = u.cross(vn);
    const Vec3d& nt = d.normals[j];
    h[static_cast<std::size_t>(bin(vn.dot(nt), -1.0, 1.0))] += 1.0f;
    h[static_cast<std::size_t>(kBins + bin(u.dot(step), -1.0, 1.0))] += 1.0f;
    h[static_cast<std::size_t>(2 * kBins +
                               bin(std::atan2(w.dot(nt), u.dot(nt)), -ulc::kPi, ulc::kPi))] += 1.0f;
    ++used;
  }
  if (used > 0)
    for (float& x : h) x *= 100.0f / static_cast<float>(used);
  return h;
}

inline double squared_distance(const Feature& a, const Feature& b) {
  double s = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) s += double(a[k] - b[k]) * double(a[k] - b[k]);
  return s;
}

/// Index of the nearest feature of `pool` to `f`.
inline std::size_t nearest_feature(const Feature& f, const std::vector<Feature>& pool) {
  std::size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < pool.size(); ++k) {
    const double d = squared_distance(f, pool[k]);
    if (d < best_d) best_d = d, best = k;
  }
  return best;
}

/// R, t with R a + t = b for the pairs, least squares (Eigen::umeyama without scaling).
inline void rigid_fit(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, Mat3d& R,
                      Vec3d& t) {
  Eigen::Matrix3Xd from(3, static_cast<Eigen::Index>(a.size())), to(3, from.cols());
  for (std::size_t i = 0; i < a.size(); ++i)
    from.col(static_cast<Eigen::Index>(i)) = a[i], to.col(static_cast<Eigen::Index>(i)) = b[i];
  const Eigen::Matrix4d T = Eigen::umeyama(from, to, false);
  R = T.topLeftCorner<3, 3>();
  t = T.topRightCorner<3, 1>();
}

}  // namespace detail

/// Downsamples `cloud`, estimates normals and FPFH features.
template <class Cloud>
Described describe(const Cloud& cloud, const Options& o) {
  Described d;
  const auto thinned = ulc::voxel_downsample(cloud, o.voxel);
  std::vector<Vec3d> pts;
  for (const auto& p : thinned.cloud.points) pts.push_back(p.template cast<double>());
  const ulc::KdTree<std::vector<Vec3d>> tree(pts);
  const auto normals = ulc::estimate_normals(pts, tree);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!normals.points[i].valid) continue;
    Vec3d n = normals.points[i].normal;
    if (n.dot(-pts[i]) < 0) n = -n;  // towards the sensor at the origin
    d.points.push_back(pts[i]);
    d.normals.push_back(n);
  }
  const ulc::KdTree<std::vector<Vec3d>> kept(d.points);
  std::vector<std::vector<std::size_t>> near(d.points.size());
  std::vector<Feature> simple(d.points.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, d.points.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<double> sq;  // the search's distances, unused
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        kept.radius(d.points[i], o.feature_radius, near[i], sq);
                        if (near[i].size() > o.max_neighbours) near[i].resize(o.max_neighbours);
                        simple[i] = detail::spfh(d, i, near[i]);
                      }
                    });
  d.features.resize(d.points.size());
  tbb::parallel_for(std::size_t{0}, d.points.size(), [&](std::size_t i) {
    Feature f = simple[i];
    std::size_t k = 0;
    Feature sum{};
    for (std::size_t j : near[i]) {
      const double dist = (d.points[j] - d.points[i]).norm();
      if (j == i || !(dist > 0.0)) continue;
      for (std::size_t b = 0; b < f.size(); ++b) sum[b] += simple[j][b] / static_cast<float>(dist);
      ++k;
    }
    if (k > 0)
      for (std::size_t b = 0; b < f.size(); ++b) f[b] += sum[b] / static_cast<float>(k);
    d.features[i] = f;
  });
  return d;
}

/// The transform that takes the target's points onto the base's (R_base_target, t).
inline Result register_frames(const Described& base, const Described& target, const Options& o) {
  Result r;
  if (base.points.size() < 3 || target.points.size() < 3) return r;
  std::vector<std::size_t> to_base(target.points.size()), to_target(base.points.size());
  tbb::parallel_for(std::size_t{0}, target.points.size(), [&](std::size_t i) {
    to_base[i] = detail::nearest_feature(target.features[i], base.features);
  });
  tbb::parallel_for(std::size_t{0}, base.points.size(), [&](std::size_t i) {
    to_target[i] = detail::nearest_feature(base.features[i], target.features);
  });
  std::vector<Vec3d> a, b;  // target points, their matched base points
  for (std::size_t i = 0; i < to_base.size(); ++i)
    if (to_target[to_base[i]] == i)
      a.push_back(target.points[i]), b.push_back(base.points[to_base[i]]);
  r.matches = a.size();
  if (a.size() < 3) return r;
  terra::SplitMix64 rng(o.seed);
  auto count_inliers = [&](const Mat3d& R, const Vec3d& t, std::vector<std::size_t>* which) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
      if ((R * a[i] + t - b[i]).norm() < o.inlier_distance) {
        ++n;
        if (which) which->push_back(i);
      }
    return n;
  };
  for (int it = 0; it < o.iterations; ++it) {
    std::size_t s[3];
    for (auto& x : s) x = static_cast<std::size_t>(rng.next() % a.size());
    if (s[0] == s[1] || s[1] == s[2] || s[0] == s[2]) continue;
    bool edges_agree = true;
    for (int e = 0; e < 3 && edges_agree; ++e) {
      const double la = (a[s[e]] - a[s[(e + 1) % 3]]).norm();
      const double lb = (b[s[e]] - b[s[(e + 1) % 3]]).norm();
      edges_agree = std::fabs(la - lb) <= o.edge_tolerance * std::max(la, lb);
    }
    if (!edges_agree) continue;
    Mat3d R;
    Vec3d t;
    detail::rigid_fit({a[s[0]], a[s[1]], a[s[2]]}, {b[s[0]], b[s[1]], b[s[2]]}, R, t);
    const std::size_t n = count_inliers(R, t, nullptr);
    if (n > r.inliers) r.inliers = n, r.rotation = R, r.translation = t, r.ok = true;
  }
  if (!r.ok) return r;
  std::vector<std::size_t> in;
  count_inliers(r.rotation, r.translation, &in);
  std::vector<Vec3d> ia, ib;
  for (std::size_t i : in) ia.push_back(a[i]), ib.push_back(b[i]);
  if (ia.size() >= 3) detail::rigid_fit(ia, ib, r.rotation, r.translation);
  return r;
}

}  // namespace fpfh_baseline
