#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <vector>

// Only the traits header: it must bring every built-in cloud type with it.
#include "ulc/core/point_traits.hpp"

namespace {

struct PlainPoint {
  float x, y, z;
};
struct RichPoint {
  double x, y, z;
  float intensity;
  double time;
  float normal_x, normal_y, normal_z;
};
struct ShortTimePoint {
  float x, y, z;
  float t;
};
struct NotAPoint {
  int a;
};

template <typename C>
double sum_of_coordinates(const C& cloud) {
  double s = 0;
  for (std::size_t i = 0; i < ulc::traits::size(cloud); ++i)
    s += static_cast<double>(ulc::traits::point(cloud, i).sum());
  return s;
}

}  // namespace

static_assert(ulc::traits::is_cloud_v<std::vector<Eigen::Vector3f>>);
static_assert(ulc::traits::is_cloud_v<Eigen::MatrixX3d>);
static_assert(ulc::traits::is_cloud_v<std::vector<PlainPoint>>);
static_assert(ulc::traits::is_cloud_v<ulc::PointCloud<double>>);
static_assert(!ulc::traits::is_cloud_v<std::vector<NotAPoint>>);
static_assert(!ulc::traits::is_cloud_v<int>);
static_assert(std::is_same_v<ulc::traits::scalar_t<std::vector<PlainPoint>>, float>);
static_assert(std::is_same_v<ulc::traits::scalar_t<std::vector<RichPoint>>, double>);
static_assert(!ulc::traits::has_time_v<std::vector<PlainPoint>>);
static_assert(ulc::traits::has_time_v<std::vector<RichPoint>>);
static_assert(ulc::traits::has_time_v<std::vector<ShortTimePoint>>);
static_assert(ulc::traits::has_intensity_v<std::vector<RichPoint>>);
static_assert(ulc::traits::has_normal_v<std::vector<RichPoint>>);
static_assert(!ulc::traits::has_normal_v<std::vector<Eigen::Vector3d>>);
static_assert(ulc::traits::is_writable_cloud_v<Eigen::MatrixX3f>);

TEST_CASE("every built-in cloud type reads the same points", "[traits]") {
  const std::vector<Eigen::Vector3d> ref = {{1, 2, 3}, {-4, 5.5, 6}, {7, -8, 9.25}};
  std::vector<Eigen::Vector3f> vec;
  Eigen::MatrixX3d mat(3, 3);
  std::vector<PlainPoint> plain;
  ulc::PointCloud<double> soa;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    vec.push_back(ref[i].cast<float>());
    mat.row(static_cast<Eigen::Index>(i)) = ref[i].transpose();
    plain.push_back({float(ref[i].x()), float(ref[i].y()), float(ref[i].z())});
    soa.points.push_back(ref[i]);
  }
  const double expected = 1 + 2 + 3 - 4 + 5.5 + 6 + 7 - 8 + 9.25;
  CHECK(sum_of_coordinates(vec) == Approx(expected));
  CHECK(sum_of_coordinates(mat) == Approx(expected));
  CHECK(sum_of_coordinates(plain) == Approx(expected));
  CHECK(sum_of_coordinates(soa) == Approx(expected));
  CHECK(ulc::traits::point(mat, 1) == Eigen::Vector3d(-4, 5.5, 6));
}

TEST_CASE("optional fields are found on structs and absent fields read as zero", "[traits]") {
  std::vector<RichPoint> rich = {{1, 2, 3, 0.5f, 0.025, 0, 0, 1}};
  CHECK(ulc::traits::has_time(rich));
  CHECK(ulc::traits::time(rich, 0) == 0.025);
  CHECK(ulc::traits::intensity(rich, 0) == 0.5);
  CHECK(ulc::traits::normal(rich, 0) == Eigen::Vector3d(0, 0, 1));

  std::vector<ShortTimePoint> short_time = {{1, 2, 3, 0.125f}};
  CHECK(ulc::traits::time(short_time, 0) == 0.125);

  std::vector<PlainPoint> plain = {{1, 2, 3}};
  CHECK_FALSE(ulc::traits::has_time(plain));
  CHECK(ulc::traits::time(plain, 0) == 0.0);
  CHECK(ulc::traits::intensity(plain, 0) == 0.0f);
}

TEST_CASE("PointCloud reports optional arrays only when they cover every point", "[traits]") {
  ulc::PointCloud<float> cloud;
  ulc::traits::resize(cloud, 2);
  ulc::traits::set_point(cloud, 0, Eigen::Vector3f(1, 2, 3));
  ulc::traits::set_point(cloud, 1, Eigen::Vector3f(4, 5, 6));
  CHECK_FALSE(ulc::traits::has_time(cloud));
  CHECK_FALSE(ulc::traits::has_intensity(cloud));
  ulc::traits::set_time(cloud, 1, 0.05);
  ulc::traits::set_intensity(cloud, 0, 7.0f);
  CHECK(ulc::traits::has_time(cloud));
  CHECK(ulc::traits::time(cloud, 0) == 0.0);
  CHECK(ulc::traits::time(cloud, 1) == 0.05);
  CHECK(ulc::traits::intensity(cloud, 0) == 7.0f);
  cloud.points.push_back(Eigen::Vector3f::Zero());  // arrays now stale: treated as absent
  CHECK_FALSE(ulc::traits::has_time(cloud));
}

TEST_CASE("writing through traits fills structs, matrices and vectors", "[traits]") {
  std::vector<RichPoint> rich;
  ulc::traits::resize(rich, 1);
  ulc::traits::set_point(rich, 0, Eigen::Vector3d(1, 2, 3));
  ulc::traits::set_time(rich, 0, 0.5);
  ulc::traits::set_intensity(rich, 0, 9.0);
  CHECK(rich[0].x == 1.0);
  CHECK(rich[0].time == 0.5);
  CHECK(rich[0].intensity == 9.0f);

  Eigen::MatrixX3f mat;
  ulc::traits::resize(mat, 2);
  ulc::traits::set_point(mat, 1, Eigen::Vector3f(4, 5, 6));
  ulc::traits::set_time(mat, 1, 0.5);  // a matrix cannot hold time: silently skipped
  CHECK(mat.rows() == 2);
  CHECK(mat(1, 2) == 6.0f);
}
