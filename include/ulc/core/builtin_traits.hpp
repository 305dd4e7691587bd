// CloudTraits for the cloud types ULC understands out of the box:
//   std::vector<Eigen::Matrix<S, 3, 1>>          points only
//   Eigen::Matrix<S, Eigen::Dynamic, 3>          one point per row
//   std::vector<P> for any struct P with arithmetic members x, y, z; members named
//     `time` or `t` (seconds since the frame timestamp), `intensity`, and
//     `normal_x, normal_y, normal_z` are picked up when present.
// ulc::PointCloud<S> has its own traits in point_cloud.hpp.
#pragma once

#include <Eigen/Core>
#include <type_traits>
#include <vector>

#include "ulc/core/point_traits.hpp"

namespace ulc {

// ---- std::vector of Eigen 3-vectors -------------------------------------------------------
template <typename S, int Options, typename Alloc>
struct CloudTraits<std::vector<Eigen::Matrix<S, 3, 1, Options, 3, 1>, Alloc>> {
  using Cloud = std::vector<Eigen::Matrix<S, 3, 1, Options, 3, 1>, Alloc>;
  using Scalar = S;
  static std::size_t size(const Cloud& c) { return c.size(); }
  static Eigen::Matrix<S, 3, 1> point(const Cloud& c, std::size_t i) { return c[i]; }
  static void resize(Cloud& c, std::size_t n) { c.resize(n); }
  static void set_point(Cloud& c, std::size_t i, const Eigen::Matrix<S, 3, 1>& p) { c[i] = p; }
};

// ---- Eigen N x 3 matrices -----------------------------------------------------------------
template <typename S, int Options, int MaxRows>
struct CloudTraits<Eigen::Matrix<S, Eigen::Dynamic, 3, Options, MaxRows, 3>> {
  using Cloud = Eigen::Matrix<S, Eigen::Dynamic, 3, Options, MaxRows, 3>;
  using Scalar = S;
  static std::size_t size(const Cloud& c) { return static_cast<std::size_t>(c.rows()); }
  static Eigen::Matrix<S, 3, 1> point(const Cloud& c, std::size_t i) {
    return c.row(static_cast<Eigen::Index>(i)).transpose();
  }
  static void resize(Cloud& c, std::size_t n) { c.resize(static_cast<Eigen::Index>(n), 3); }
  static void set_point(Cloud& c, std::size_t i, const Eigen::Matrix<S, 3, 1>& p) {
    c.row(static_cast<Eigen::Index>(i)) = p.transpose();
  }
};

// ---- std::vector of a user struct with x, y, z members --------------------------------------
namespace detail {

template <typename P, typename = void>
struct has_xyz_members : std::false_type {};
template <typename P>
struct has_xyz_members<P, void_t<decltype(std::declval<P&>().x), decltype(std::declval<P&>().y),
                                 decltype(std::declval<P&>().z)>>
    : std::bool_constant<std::is_arithmetic<decltype(std::declval<P&>().x)>::value> {};

#define ULC_DETECT_MEMBER(NAME, MEMBER)                       \
  template <typename P, typename = void>                      \
  struct NAME : std::false_type {};                           \
  template <typename P>                                       \
  struct NAME<P, void_t<decltype(std::declval<P&>().MEMBER)>> \
      : std::is_arithmetic<std::remove_reference_t<decltype(std::declval<P&>().MEMBER)>> {};
ULC_DETECT_MEMBER(has_time_member, time)
ULC_DETECT_MEMBER(has_t_member, t)
ULC_DETECT_MEMBER(has_intensity_member, intensity)
ULC_DETECT_MEMBER(has_normal_x_member, normal_x)
#undef ULC_DETECT_MEMBER

template <typename P>
constexpr bool struct_has_time = has_time_member<P>::value || has_t_member<P>::value;

template <typename P>
auto& struct_time(P& p) {
  if constexpr (has_time_member<P>::value)
    return p.time;
  else
    return p.t;
}
template <typename P>
const auto& struct_time(const P& p) {
  if constexpr (has_time_member<P>::value)
    return p.time;
  else
    return p.t;
}

/// Base traits for a vector of structs; the optional fields are added by the mixins below.
template <typename P, typename Alloc>
struct StructVectorCore {
  using Cloud = std::vector<P, Alloc>;
  using Scalar = std::remove_cv_t<std::remove_reference_t<decltype(std::declval<P&>().x)>>;
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  static std::size_t size(const Cloud& c) { return c.size(); }
  static Vec3 point(const Cloud& c, std::size_t i) { return Vec3(c[i].x, c[i].y, c[i].z); }
  static void resize(Cloud& c, std::size_t n) { c.resize(n); }
  static void set_point(Cloud& c, std::size_t i, const Vec3& p) {
    using X = std::remove_reference_t<decltype(c[i].x)>;
    c[i].x = static_cast<X>(p.x());
    c[i].y = static_cast<X>(p.y());
    c[i].z = static_cast<X>(p.z());
  }
};

template <typename P, typename Alloc, bool HasTime = struct_has_time<P>>
struct StructVectorTime : StructVectorCore<P, Alloc> {};
template <typename P, typename Alloc>
struct StructVectorTime<P, Alloc, true> : StructVectorCore<P, Alloc> {
  using Cloud = std::vector<P, Alloc>;
  static double time(const Cloud& c, std::size_t i) {
    return static_cast<double>(struct_time(c[i]));
  }
  static void set_time(Cloud& c, std::size_t i, double t) {
    using T = std::remove_reference_t<decltype(struct_time(c[i]))>;
    struct_time(c[i]) = static_cast<T>(t);
  }
};

template <typename P, typename Alloc, bool HasIntensity = has_intensity_member<P>::value>
struct StructVectorIntensity : StructVectorTime<P, Alloc> {};
template <typename P, typename Alloc>
struct StructVectorIntensity<P, Alloc, true> : StructVectorTime<P, Alloc> {
  using Cloud = std::vector<P, Alloc>;
  using Scalar = typename StructVectorCore<P, Alloc>::Scalar;
  static Scalar intensity(const Cloud& c, std::size_t i) {
    return static_cast<Scalar>(c[i].intensity);
  }
  static void set_intensity(Cloud& c, std::size_t i, Scalar v) {
    c[i].intensity = static_cast<std::remove_reference_t<decltype(c[i].intensity)>>(v);
  }
};

template <typename P, typename Alloc, bool HasNormal = has_normal_x_member<P>::value>
struct StructVectorTraits : StructVectorIntensity<P, Alloc> {};
template <typename P, typename Alloc>
struct StructVectorTraits<P, Alloc, true> : StructVectorIntensity<P, Alloc> {
  using Cloud = std::vector<P, Alloc>;
  using Vec3 = typename StructVectorCore<P, Alloc>::Vec3;
  static Vec3 normal(const Cloud& c, std::size_t i) {
    return Vec3(c[i].normal_x, c[i].normal_y, c[i].normal_z);
  }
  static void set_normal(Cloud& c, std::size_t i, const Vec3& n) {
    using N = std::remove_reference_t<decltype(c[i].normal_x)>;
    c[i].normal_x = static_cast<N>(n.x());
    c[i].normal_y = static_cast<N>(n.y());
    c[i].normal_z = static_cast<N>(n.z());
  }
};

}  // namespace detail

template <typename P, typename Alloc>
struct CloudTraits<std::vector<P, Alloc>, std::enable_if_t<detail::has_xyz_members<P>::value>>
    : detail::StructVectorTraits<P, Alloc> {};

}  // namespace ulc
