#include <tbb/task_arena.h>
#include <Eigen/Core>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "ulc/core/cloud.hpp"
#include "ulc/core/median.hpp"
#include "ulc/core/normals.hpp"

namespace {

template <typename S>
std::vector<ulc::Vec3<S>> noisy_plane(const Eigen::Vector3d& centre, const Eigen::Vector3d& n,
                                      std::size_t count, double half_extent, double noise,
                                      unsigned seed) {
  const Eigen::Vector3d e1 = n.unitOrthogonal();
  const Eigen::Vector3d e2 = n.cross(e1);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-half_extent, half_extent);
  std::normal_distribution<double> g(0.0, noise);
  std::vector<ulc::Vec3<S>> cloud;
  for (std::size_t i = 0; i < count; ++i)
    cloud.push_back((centre + u(rng) * e1 + u(rng) * e2 + g(rng) * n).cast<S>());
  return cloud;
}

constexpr double kDeg = 3.14159265358979323846 / 180.0;

}  // namespace

TEMPLATE_TEST_CASE("normals of a noisy plane: within a degree, oriented, planar", "[normals]",
                   float, double) {
  using S = TestType;
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.2, 1.0).normalized();
  const Eigen::Vector3d centre(4.0, -2.0, 1.5);
  // 4000 points on 8 m x 8 m: neighbours ~0.13 m apart; 3 mm noise.
  const auto cloud = noisy_plane<S>(centre, n, 4000, 4.0, 0.003, 71);
  ulc::NormalEstimationOptions options;
  options.viewpoint = centre + 10.0 * n;  // the sensor is on the +n side
  const auto result = ulc::estimate_normals(cloud, options);
  REQUIRE(result.ok());
  REQUIRE(result.points.size() == cloud.size());
  CHECK(result.valid_count == cloud.size());
  std::vector<double> angles, planarity;
  for (const auto& p : result.points) {
    REQUIRE(p.valid);
    CHECK(p.normal.norm() == Approx(1.0).epsilon(1e-5));
    CHECK(p.normal.template cast<double>().dot(n) > 0.0);  // oriented towards the viewpoint
    CHECK(p.eigenvalues[0] <= p.eigenvalues[1]);
    CHECK(p.eigenvalues[1] <= p.eigenvalues[2]);
    angles.push_back(std::acos(std::min(1.0, p.normal.template cast<double>().dot(n))));
    planarity.push_back(static_cast<double>(p.planarity));
  }
  std::sort(angles.begin(), angles.end());
  CHECK(angles[angles.size() / 2] < 1.0 * kDeg);         // median
  CHECK(angles[angles.size() * 95 / 100] < 2.5 * kDeg);  // 95th percentile
  CHECK(angles.back() < 10.0 * kDeg);  // worst: a lopsided neighbourhood at the patch edge
  CHECK(ulc::upper_median(planarity) > 0.95);
  CHECK(*std::min_element(planarity.begin(), planarity.end()) > 0.5);

  // The opposite viewpoint flips every normal.
  options.viewpoint = centre - 10.0 * n;
  const auto flipped = ulc::estimate_normals(cloud, options);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    CHECK(flipped.points[i].normal == (-result.points[i].normal).eval());
}

TEST_CASE("normals of an isotropic blob have low planarity", "[normals]") {
  std::mt19937 rng(81);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Vector3d> blob(3000);
  for (auto& p : blob) p = Eigen::Vector3d(g(rng), g(rng), g(rng));
  ulc::NormalEstimationOptions options;
  options.k = 30;
  const auto result = ulc::estimate_normals(blob, options);
  REQUIRE(result.ok());
  std::vector<double> planarity;
  for (const auto& p : result.points) planarity.push_back(p.planarity);
  CHECK(ulc::upper_median(planarity) < 0.45);

  // The same k on a plane scores far higher: the score separates the two shapes.
  const auto plane =
      noisy_plane<double>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 3000, 3.0, 0.003, 82);
  const auto plane_result = ulc::estimate_normals(plane, options);
  std::vector<double> plane_planarity;
  for (const auto& p : plane_result.points) plane_planarity.push_back(p.planarity);
  CHECK(ulc::upper_median(plane_planarity) > 0.95);
}

TEST_CASE("normals are invalid on lines, coincident points and tiny clouds", "[normals]") {
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 50; ++i) line.emplace_back(0.1 * i, 0.2 * i, -0.05 * i);
  const auto on_line = ulc::estimate_normals(line);
  REQUIRE(on_line.ok());
  CHECK(on_line.valid_count == 0);
  CHECK(on_line.points[10].normal == Eigen::Vector3d::Zero());

  const std::vector<Eigen::Vector3d> same(20, Eigen::Vector3d(1, 2, 3));
  CHECK(ulc::estimate_normals(same).valid_count == 0);

  const std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  const auto tiny = ulc::estimate_normals(two);
  REQUIRE(tiny.ok());
  CHECK(tiny.points.size() == 2);
  CHECK(tiny.valid_count == 0);

  ulc::NormalEstimationOptions bad;
  bad.k = 2;
  CHECK(ulc::estimate_normals(line, bad).status == ulc::NormalsStatus::invalid_options);
}

TEMPLATE_TEST_CASE("normals are bit-identical for 1 and 2 threads", "[normals][threads]", float,
                   double) {
  using S = TestType;
  auto cloud =
      noisy_plane<S>(Eigen::Vector3d(1, 1, 1), Eigen::Vector3d::UnitY(), 3000, 5.0, 0.05, 91);
  const auto blob =
      noisy_plane<S>(Eigen::Vector3d(0, 9, 0), Eigen::Vector3d::UnitX(), 2000, 1.0, 0.5, 92);
  cloud.insert(cloud.end(), blob.begin(), blob.end());
  const ulc::KdTree<std::vector<ulc::Vec3<S>>> tree(cloud);
  auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    return arena.execute([&] { return ulc::estimate_normals(cloud, tree); });
  };
  const auto one = run(1);
  const auto two = run(2);
  REQUIRE(one.points.size() == two.points.size());
  CHECK(one.valid_count == two.valid_count);
  for (std::size_t i = 0; i < one.points.size(); ++i) {
    CHECK(one.points[i].normal == two.points[i].normal);
    CHECK(one.points[i].eigenvalues == two.points[i].eigenvalues);
    CHECK(one.points[i].planarity == two.points[i].planarity);
  }
}
