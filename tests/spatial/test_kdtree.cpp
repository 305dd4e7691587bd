#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <memory>
#include <tuple>
#include <vector>

#include "spatial_test_util.hpp"
#include "ulc/core/cloud.hpp"
#include "ulc/core/kdtree.hpp"

using spatial_test::brute_force_sorted;
using spatial_test::random_cloud;

namespace {

struct PlainPoint {
  float x, y, z;
};

/// Random points plus exact copies of some of them (ties the tree must break by index).
template <typename S>
std::vector<ulc::Vec3<S>> cloud_with_duplicates(unsigned seed) {
  auto cloud = random_cloud<S>(1500, S(5), seed);
  for (std::size_t i = 0; i < 300; i += 3) cloud.push_back(cloud[i]);
  cloud.push_back(cloud[7]);
  cloud.push_back(cloud[7]);
  return cloud;
}

template <typename S>
void check_knn(const ulc::KdTree<std::vector<ulc::Vec3<S>>>& tree,
               const std::vector<ulc::Vec3<S>>& cloud, const ulc::Vec3<S>& q, std::size_t k) {
  const auto expected = brute_force_sorted(cloud, q);
  std::vector<std::size_t> idx;
  std::vector<S> d2;
  const std::size_t found = tree.knn(q, k, idx, d2);
  REQUIRE(found == std::min(k, expected.size()));
  REQUIRE(idx.size() == found);
  for (std::size_t j = 0; j < found; ++j) {
    CHECK(idx[j] == expected[j].second);
    CHECK(d2[j] == expected[j].first);
  }
}

template <typename S>
void check_radius(const ulc::KdTree<std::vector<ulc::Vec3<S>>>& tree,
                  const std::vector<ulc::Vec3<S>>& cloud, const ulc::Vec3<S>& q, S r) {
  const auto all = brute_force_sorted(cloud, q);
  std::vector<std::size_t> idx;
  std::vector<S> d2;
  const std::size_t found = tree.radius(q, r, idx, d2);
  std::size_t expected = 0;
  while (expected < all.size() && all[expected].first <= r * r) ++expected;
  REQUIRE(found == expected);
  REQUIRE(idx.size() == found);
  for (std::size_t j = 0; j < found; ++j) {
    CHECK(idx[j] == all[j].second);
    CHECK(d2[j] == all[j].first);
  }
}

}  // namespace

TEMPLATE_TEST_CASE("kd-tree kNN equals brute force, ties broken by index", "[kdtree]", float,
                   double) {
  using S = TestType;
  const auto cloud = cloud_with_duplicates<S>(11);
  const ulc::KdTree<std::vector<ulc::Vec3<S>>> tree(cloud);
  REQUIRE(tree.size() == cloud.size());
  auto queries = random_cloud<S>(60, S(6), 12);
  for (std::size_t i = 0; i < 40; ++i) queries.push_back(cloud[i * 7]);  // queries on points
  for (std::size_t k : {1u, 2u, 5u, 10u, 37u}) {
    INFO("k = " << k);
    for (const auto& q : queries) check_knn(tree, cloud, q, k);
  }
  // nearest() agrees with knn(.., 1, ..), including on a duplicated point (lowest index wins).
  std::size_t index = 0;
  S d2 = -1;
  REQUIRE(tree.nearest(cloud[7], index, d2));
  CHECK(index == 7);
  CHECK(d2 == S(0));
}

TEMPLATE_TEST_CASE("kd-tree kNN on a regular grid (many equal distances)", "[kdtree]", float,
                   double) {
  using S = TestType;
  std::vector<ulc::Vec3<S>> grid;
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y)
      for (int z = 0; z < 8; ++z) grid.emplace_back(S(x), S(y), S(z));
  const ulc::KdTree<std::vector<ulc::Vec3<S>>> tree(grid, 4);
  for (std::size_t k : {6u, 7u, 19u, 27u}) {
    check_knn(tree, grid, ulc::Vec3<S>(3, 4, 3), k);
    check_knn(tree, grid, ulc::Vec3<S>(S(3.5), S(3.5), S(3.5)), k);
    check_knn(tree, grid, ulc::Vec3<S>(0, 0, 0), k);
  }
}

TEMPLATE_TEST_CASE("kd-tree radius search equals brute force (closed ball)", "[kdtree]", float,
                   double) {
  using S = TestType;
  const auto cloud = cloud_with_duplicates<S>(21);
  const ulc::KdTree<std::vector<ulc::Vec3<S>>> tree(cloud);
  auto queries = random_cloud<S>(40, S(6), 22);
  queries.push_back(cloud[3]);
  for (S r : {S(0), S(0.3), S(1), S(2.5)}) {
    INFO("r = " << r);
    for (const auto& q : queries) check_radius(tree, cloud, q, r);
  }
  // A point exactly at distance r is inside.
  const std::vector<ulc::Vec3<S>> unit = {{1, 0, 0}, {0, 2, 0}, {0, 0, -1}};
  const ulc::KdTree<std::vector<ulc::Vec3<S>>> unit_tree(unit);
  std::vector<std::size_t> idx;
  std::vector<S> d2;
  CHECK(unit_tree.radius(ulc::Vec3<S>::Zero(), S(1), idx, d2) == 2);
  CHECK(idx == std::vector<std::size_t>{0, 2});
  CHECK(unit_tree.radius(ulc::Vec3<S>::Zero(), S(-1), idx, d2) == 0);
}

TEST_CASE("kd-tree on an empty cloud is valid and finds nothing", "[kdtree]") {
  const std::vector<Eigen::Vector3d> empty;
  const ulc::KdTree<std::vector<Eigen::Vector3d>> tree(empty);
  const ulc::KdTree<std::vector<Eigen::Vector3d>> default_tree;
  std::vector<std::size_t> idx{1, 2};
  std::vector<double> d2{1, 2};
  for (const auto* t : {&tree, &default_tree}) {
    CHECK(t->empty());
    CHECK(t->knn(Eigen::Vector3d::Zero(), 5, idx, d2) == 0);
    CHECK(idx.empty());
    CHECK(t->radius(Eigen::Vector3d::Zero(), 10.0, idx, d2) == 0);
    std::size_t i = 0;
    double d = 0;
    CHECK_FALSE(t->nearest(Eigen::Vector3d::Zero(), i, d));
  }
}

TEST_CASE("kd-tree handles k larger than the cloud, k = 0 and non-finite queries", "[kdtree]") {
  const std::vector<Eigen::Vector3f> cloud = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  const ulc::KdTree<std::vector<Eigen::Vector3f>> tree(cloud);
  std::vector<std::size_t> idx;
  std::vector<float> d2;
  CHECK(tree.knn(Eigen::Vector3f(2, 2, 2), 10, idx, d2) == 3);
  CHECK(idx == std::vector<std::size_t>{2, 1, 0});
  CHECK(tree.knn(Eigen::Vector3f(2, 2, 2), 0, idx, d2) == 0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  CHECK(tree.knn(Eigen::Vector3f(nan, 0, 0), 2, idx, d2) == 0);
  CHECK(tree.radius(Eigen::Vector3f(0, std::numeric_limits<float>::infinity(), 0), 5.f, idx, d2) ==
        0);
}

TEST_CASE("kd-tree skips non-finite points and reports cloud indices", "[kdtree]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto cloud = random_cloud<double>(500, 3.0, 31);
  cloud[0] = Eigen::Vector3d(nan, 0, 0);
  cloud[10] = Eigen::Vector3d(0, inf, 0);
  cloud[499] = Eigen::Vector3d(0, 0, -inf);
  const ulc::KdTree<std::vector<Eigen::Vector3d>> tree(cloud);
  CHECK(tree.size() == 497);
  CHECK(tree.skipped() == 3);
  for (const auto& q : random_cloud<double>(30, 3.0, 32)) {
    check_knn(tree, cloud, q, 8);
    check_radius(tree, cloud, q, 1.0);
  }
  // Only non-finite points: an empty tree, no crash.
  const std::vector<Eigen::Vector3d> all_bad = {{nan, nan, nan}, {inf, 0, 0}};
  const ulc::KdTree<std::vector<Eigen::Vector3d>> bad_tree(all_bad);
  std::vector<std::size_t> idx;
  std::vector<double> d2;
  CHECK(bad_tree.empty());
  CHECK(bad_tree.knn(Eigen::Vector3d::Zero(), 1, idx, d2) == 0);
}

TEST_CASE("kd-tree reads any traits cloud and outlives it", "[kdtree]") {
  const auto ref = random_cloud<float>(300, 2.f, 41);
  std::vector<PlainPoint> plain;
  ulc::PointCloud<float> soa;
  Eigen::MatrixX3f mat(static_cast<Eigen::Index>(ref.size()), 3);
  for (std::size_t i = 0; i < ref.size(); ++i) {
    plain.push_back({ref[i].x(), ref[i].y(), ref[i].z()});
    soa.points.push_back(ref[i]);
    mat.row(static_cast<Eigen::Index>(i)) = ref[i].transpose();
  }
  const ulc::KdTree<std::vector<PlainPoint>> plain_tree(plain);
  const ulc::KdTree<ulc::PointCloud<float>> soa_tree(soa);
  auto mat_tree = std::make_unique<ulc::KdTree<Eigen::MatrixX3f>>(mat);
  plain.clear();  // the trees hold their own copies
  soa.clear();
  mat.resize(0, 3);
  const ulc::KdTree<Eigen::MatrixX3f> moved(std::move(*mat_tree));
  mat_tree.reset();
  for (const auto& q : random_cloud<float>(20, 2.f, 42)) {
    const auto expected = brute_force_sorted(ref, q);
    std::vector<std::size_t> a, b, c;
    std::vector<float> da, db, dc;
    plain_tree.knn(q, 6, a, da);
    soa_tree.knn(q, 6, b, db);
    moved.knn(q, 6, c, dc);
    for (std::size_t j = 0; j < 6; ++j) {
      CHECK(a[j] == expected[j].second);
      CHECK(b[j] == expected[j].second);
      CHECK(c[j] == expected[j].second);
    }
  }
}

TEST_CASE("concurrent kd-tree queries from TBB tasks equal serial ones", "[kdtree][threads]") {
  const auto cloud = random_cloud<float>(5000, 10.f, 51);
  const ulc::KdTree<std::vector<Eigen::Vector3f>> tree(cloud);
  const auto queries = random_cloud<float>(4000, 10.f, 52);
  constexpr std::size_t k = 8;
  auto run = [&](int threads) {
    std::vector<std::size_t> idx(queries.size() * k);
    std::vector<float> d2(queries.size() * k);
    std::vector<std::size_t> radius_counts(queries.size());
    tbb::task_arena arena(threads);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 16),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          std::vector<std::size_t> ri;
                          std::vector<float> rd;
                          for (std::size_t i = r.begin(); i != r.end(); ++i) {
                            tree.knn(queries[i], k, &idx[i * k], &d2[i * k]);
                            radius_counts[i] = tree.radius(queries[i], 1.0f, ri, rd);
                          }
                        });
    });
    return std::make_tuple(idx, d2, radius_counts);
  };
  std::vector<std::size_t> serial_idx(queries.size() * k);
  std::vector<float> serial_d2(queries.size() * k);
  std::vector<std::size_t> serial_counts(queries.size());
  std::vector<std::size_t> ri;
  std::vector<float> rd;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    tree.knn(queries[i], k, &serial_idx[i * k], &serial_d2[i * k]);
    serial_counts[i] = tree.radius(queries[i], 1.0f, ri, rd);
  }
  for (int threads : {1, 2}) {
    INFO("threads = " << threads);
    const auto [idx, d2, counts] = run(threads);
    CHECK(idx == serial_idx);
    CHECK(d2 == serial_d2);
    CHECK(counts == serial_counts);
  }
}
