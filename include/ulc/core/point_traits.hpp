// Point traits: the one customisation point through which every ULC algorithm reads a cloud.
//
// A cloud type C plugs in by specialising ulc::CloudTraits<C> with
//   using Scalar = float | double;
//   static std::size_t size(const C&);
//   static Eigen::Matrix<Scalar, 3, 1> point(const C&, std::size_t i);   // x, y, z
// and, optionally (each detected at compile time):
//   static double time(const C&, std::size_t i);       // seconds since the frame timestamp
//   static Scalar intensity(const C&, std::size_t i);
//   static Eigen::Matrix<Scalar, 3, 1> normal(const C&, std::size_t i);
//   static bool has_time(const C&) / has_intensity / has_normal   // runtime presence (SoA clouds)
// For clouds the I/O layer writes into (optional, detected likewise):
//   static void resize(C&, std::size_t n);
//   static void set_point(C&, std::size_t i, const Eigen::Matrix<Scalar, 3, 1>&);
//   static void set_time(C&, std::size_t i, double), set_intensity(...), set_normal(...)
//
// Algorithms call the free functions in ulc::traits (size, point, time, ...), never the
// specialisation directly, so a missing trait stops compilation with one readable static_assert.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <type_traits>
#include <utility>

namespace ulc {

/// Specialise for your cloud type. The primary template is deliberately empty.
template <typename Cloud, typename Enable = void>
struct CloudTraits {};

namespace detail {

template <typename...>
using void_t = void;

template <typename T, typename = void>
struct has_scalar : std::false_type {};
template <typename T>
struct has_scalar<T, void_t<typename CloudTraits<T>::Scalar>> : std::true_type {};

template <typename T, typename = void>
struct has_size : std::false_type {};
template <typename T>
struct has_size<T, void_t<decltype(CloudTraits<T>::size(std::declval<const T&>()))>>
    : std::true_type {};

template <typename T, typename = void>
struct has_point : std::false_type {};
template <typename T>
struct has_point<T,
                 void_t<decltype(CloudTraits<T>::point(std::declval<const T&>(), std::size_t{}))>>
    : std::true_type {};

#define ULC_DETECT_CLOUD_TRAIT(NAME, CALL) \
  template <typename T, typename = void>   \
  struct NAME : std::false_type {};        \
  template <typename T>                    \
  struct NAME<T, void_t<decltype(CloudTraits<T>::CALL)>> : std::true_type {};

ULC_DETECT_CLOUD_TRAIT(has_time_trait, time(std::declval<const T&>(), std::size_t{}))
ULC_DETECT_CLOUD_TRAIT(has_intensity_trait, intensity(std::declval<const T&>(), std::size_t{}))
ULC_DETECT_CLOUD_TRAIT(has_normal_trait, normal(std::declval<const T&>(), std::size_t{}))
ULC_DETECT_CLOUD_TRAIT(has_runtime_time, has_time(std::declval<const T&>()))
ULC_DETECT_CLOUD_TRAIT(has_runtime_intensity, has_intensity(std::declval<const T&>()))
ULC_DETECT_CLOUD_TRAIT(has_runtime_normal, has_normal(std::declval<const T&>()))
ULC_DETECT_CLOUD_TRAIT(has_resize, resize(std::declval<T&>(), std::size_t{}))
ULC_DETECT_CLOUD_TRAIT(has_set_time, set_time(std::declval<T&>(), std::size_t{}, 0.0))
ULC_DETECT_CLOUD_TRAIT(has_set_intensity, set_intensity(std::declval<T&>(), std::size_t{},
                                                        typename CloudTraits<T>::Scalar{}))
ULC_DETECT_CLOUD_TRAIT(has_set_normal,
                       set_normal(std::declval<T&>(), std::size_t{},
                                  Eigen::Matrix<typename CloudTraits<T>::Scalar, 3, 1>{}))
ULC_DETECT_CLOUD_TRAIT(has_set_point,
                       set_point(std::declval<T&>(), std::size_t{},
                                 Eigen::Matrix<typename CloudTraits<T>::Scalar, 3, 1>{}))
#undef ULC_DETECT_CLOUD_TRAIT

}  // namespace detail

namespace traits {

template <typename C>
using remove_cvref_t = std::remove_cv_t<std::remove_reference_t<C>>;

/// True when CloudTraits<C> provides Scalar, size and point.
template <typename C>
constexpr bool is_cloud_v = detail::has_scalar<remove_cvref_t<C>>::value&&
    detail::has_size<remove_cvref_t<C>>::value&& detail::has_point<remove_cvref_t<C>>::value;

/// True when the I/O layer can fill C (resize + set_point).
template <typename C>
constexpr bool is_writable_cloud_v = is_cloud_v<C>&& detail::has_resize<remove_cvref_t<C>>::value&&
    detail::has_set_point<remove_cvref_t<C>>::value;

template <typename C>
constexpr bool has_time_v = detail::has_time_trait<remove_cvref_t<C>>::value;
template <typename C>
constexpr bool has_intensity_v = detail::has_intensity_trait<remove_cvref_t<C>>::value;
template <typename C>
constexpr bool has_normal_v = detail::has_normal_trait<remove_cvref_t<C>>::value;

#define ULC_REQUIRE_CLOUD(C)                                                                    \
  static_assert(::ulc::traits::is_cloud_v<C>,                                                   \
                "ulc: this type is not a point cloud. Specialise ulc::CloudTraits<YourCloud> "  \
                "with `using Scalar`, `static size(const C&)` and `static point(const C&, i)` " \
                "(see include/ulc/core/point_traits.hpp and examples/custom_point_type.cpp)")

template <typename C>
struct scalar_of {
  ULC_REQUIRE_CLOUD(C);
  using type = typename CloudTraits<remove_cvref_t<C>>::Scalar;
};
template <typename C>
using scalar_t = typename scalar_of<C>::type;

template <typename C>
using vector3_t = Eigen::Matrix<scalar_t<C>, 3, 1>;

template <typename C>
std::size_t size(const C& cloud) {
  ULC_REQUIRE_CLOUD(C);
  return static_cast<std::size_t>(CloudTraits<C>::size(cloud));
}

template <typename C>
vector3_t<C> point(const C& cloud, std::size_t i) {
  ULC_REQUIRE_CLOUD(C);
  return CloudTraits<C>::point(cloud, i).template cast<scalar_t<C>>();
}

/// Whether this particular cloud carries per-point times (compile-time capability and, for
/// struct-of-arrays clouds, runtime presence).
template <typename C>
bool has_time(const C& cloud) {
  if constexpr (!has_time_v<C>) {
    (void)cloud;
    return false;
  } else if constexpr (detail::has_runtime_time<C>::value) {
    return CloudTraits<C>::has_time(cloud);
  } else {
    (void)cloud;
    return true;
  }
}

template <typename C>
bool has_intensity(const C& cloud) {
  if constexpr (!has_intensity_v<C>) {
    (void)cloud;
    return false;
  } else if constexpr (detail::has_runtime_intensity<C>::value) {
    return CloudTraits<C>::has_intensity(cloud);
  } else {
    (void)cloud;
    return true;
  }
}

template <typename C>
bool has_normal(const C& cloud) {
  if constexpr (!has_normal_v<C>) {
    (void)cloud;
    return false;
  } else if constexpr (detail::has_runtime_normal<C>::value) {
    return CloudTraits<C>::has_normal(cloud);
  } else {
    (void)cloud;
    return true;
  }
}

/// Per-point time in seconds since the frame timestamp; 0 when the cloud has none.
template <typename C>
double time(const C& cloud, std::size_t i) {
  ULC_REQUIRE_CLOUD(C);
  if constexpr (has_time_v<C>) {
    return has_time(cloud) ? static_cast<double>(CloudTraits<C>::time(cloud, i)) : 0.0;
  } else {
    (void)cloud;
    (void)i;
    return 0.0;
  }
}

/// Per-point intensity; 0 when the cloud has none.
template <typename C>
scalar_t<C> intensity(const C& cloud, std::size_t i) {
  ULC_REQUIRE_CLOUD(C);
  if constexpr (has_intensity_v<C>) {
    return has_intensity(cloud) ? static_cast<scalar_t<C>>(CloudTraits<C>::intensity(cloud, i))
                                : scalar_t<C>(0);
  } else {
    (void)cloud;
    (void)i;
    return scalar_t<C>(0);
  }
}

/// Per-point normal; zero vector when the cloud has none.
template <typename C>
vector3_t<C> normal(const C& cloud, std::size_t i) {
  ULC_REQUIRE_CLOUD(C);
  if constexpr (has_normal_v<C>) {
    return has_normal(cloud)
               ? vector3_t<C>(CloudTraits<C>::normal(cloud, i).template cast<scalar_t<C>>())
               : vector3_t<C>::Zero();
  } else {
    (void)cloud;
    (void)i;
    return vector3_t<C>::Zero();
  }
}

#define ULC_REQUIRE_WRITABLE_CLOUD(C)                                                             \
  static_assert(::ulc::traits::is_writable_cloud_v<C>,                                            \
                "ulc: cannot write into this cloud type. Its CloudTraits needs `static "          \
                "resize(C&, n)` and `static set_point(C&, i, const Eigen::Matrix<Scalar,3,1>&)` " \
                "(see include/ulc/core/point_traits.hpp)")

template <typename C>
void resize(C& cloud, std::size_t n) {
  ULC_REQUIRE_WRITABLE_CLOUD(C);
  CloudTraits<C>::resize(cloud, n);
}

template <typename C>
void set_point(C& cloud, std::size_t i, const vector3_t<C>& p) {
  ULC_REQUIRE_WRITABLE_CLOUD(C);
  CloudTraits<C>::set_point(cloud, i, p);
}

/// Optional setters: silently skipped when the type cannot hold the field.
template <typename C>
void set_time(C& cloud, std::size_t i, double t) {
  if constexpr (detail::has_set_time<C>::value)
    CloudTraits<C>::set_time(cloud, i, t);
  else
    (void)cloud, (void)i, (void)t;
}

template <typename C>
void set_intensity(C& cloud, std::size_t i, scalar_t<C> v) {
  if constexpr (detail::has_set_intensity<C>::value)
    CloudTraits<C>::set_intensity(cloud, i, v);
  else
    (void)cloud, (void)i, (void)v;
}

template <typename C>
void set_normal(C& cloud, std::size_t i, const vector3_t<C>& n) {
  if constexpr (detail::has_set_normal<C>::value)
    CloudTraits<C>::set_normal(cloud, i, n);
  else
    (void)cloud, (void)i, (void)n;
}

template <typename C>
constexpr bool can_store_time_v = detail::has_set_time<remove_cvref_t<C>>::value;
template <typename C>
constexpr bool can_store_intensity_v = detail::has_set_intensity<remove_cvref_t<C>>::value;
template <typename C>
constexpr bool can_store_normal_v = detail::has_set_normal<remove_cvref_t<C>>::value;

}  // namespace traits
}  // namespace ulc

// The built-in specialisations come with the traits, so that no translation unit can see the
// primary template for a built-in cloud type while another sees its specialisation.
#include "ulc/core/builtin_traits.hpp"  // IWYU pragma: export
#include "ulc/core/point_cloud.hpp"     // IWYU pragma: export
