// ulc::PointCloud<Scalar>: ULC's own struct-of-arrays cloud. Points are always present;
// times, intensities and normals are present when their array has one entry per point.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "ulc/core/point_traits.hpp"

namespace ulc {

template <typename ScalarT>
struct PointCloud {
  using Scalar = ScalarT;
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;

  std::vector<Vec3> points;
  std::vector<double> times;        ///< seconds since the frame timestamp (empty: none)
  std::vector<Scalar> intensities;  ///< empty: none
  std::vector<Vec3> normals;        ///< empty: none

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_times() const { return !points.empty() && times.size() == points.size(); }
  bool has_intensities() const { return !points.empty() && intensities.size() == points.size(); }
  bool has_normals() const { return !points.empty() && normals.size() == points.size(); }

  void clear() {
    points.clear();
    times.clear();
    intensities.clear();
    normals.clear();
  }
  void reserve(std::size_t n) {
    points.reserve(n);
    times.reserve(n);
    intensities.reserve(n);
  }
};

template <typename S>
struct CloudTraits<PointCloud<S>> {
  using Cloud = PointCloud<S>;
  using Scalar = S;
  using Vec3 = Eigen::Matrix<S, 3, 1>;
  static std::size_t size(const Cloud& c) { return c.points.size(); }
  static Vec3 point(const Cloud& c, std::size_t i) { return c.points[i]; }

  static bool has_time(const Cloud& c) { return c.has_times(); }
  static double time(const Cloud& c, std::size_t i) { return c.times[i]; }
  static bool has_intensity(const Cloud& c) { return c.has_intensities(); }
  static S intensity(const Cloud& c, std::size_t i) { return c.intensities[i]; }
  static bool has_normal(const Cloud& c) { return c.has_normals(); }
  static Vec3 normal(const Cloud& c, std::size_t i) { return c.normals[i]; }

  static void resize(Cloud& c, std::size_t n) { c.points.resize(n); }
  static void set_point(Cloud& c, std::size_t i, const Vec3& p) { c.points[i] = p; }
  // The optional arrays grow on first use so that a cloud never claims a field it lacks.
  static void set_time(Cloud& c, std::size_t i, double t) {
    if (c.times.size() != c.points.size()) c.times.assign(c.points.size(), 0.0);
    c.times[i] = t;
  }
  static void set_intensity(Cloud& c, std::size_t i, S v) {
    if (c.intensities.size() != c.points.size()) c.intensities.assign(c.points.size(), S(0));
    c.intensities[i] = v;
  }
  static void set_normal(Cloud& c, std::size_t i, const Vec3& n) {
    if (c.normals.size() != c.points.size()) c.normals.assign(c.points.size(), Vec3::Zero());
    c.normals[i] = n;
  }
};

using PointCloudf = PointCloud<float>;
using PointCloudd = PointCloud<double>;

}  // namespace ulc
