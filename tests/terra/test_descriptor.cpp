#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "terra/descriptor.hpp"
#include "terra/kdtree_lookup.hpp"
#include "terra/lattice.hpp"
#include "terra_test_util.hpp"
#include "ulc/core/cloud.hpp"

namespace {

/// Random points in all directions, ranges 0.1 .. 80 m, a few exact duplicates of directions
/// at other ranges (so cells see several points), and invalid points.
template <typename S>
std::vector<Eigen::Matrix<S, 3, 1>> random_cloud(std::size_t n, std::uint64_t seed) {
  const auto dirs = terra_test::random_directions(n, seed);
  std::vector<Eigen::Matrix<S, 3, 1>> cloud;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = 0.1 + 80.0 * double((i * 7919) % 1000) / 1000.0;
    cloud.push_back((dirs[i] * r).cast<S>());
    if (i % 10 == 0) cloud.push_back((dirs[i] * (r * 0.5 + 1.0)).cast<S>());
  }
  const S nan = std::numeric_limits<S>::quiet_NaN();
  cloud.push_back({nan, S(1), S(2)});
  cloud.push_back({std::numeric_limits<S>::infinity(), S(0), S(0)});
  cloud.push_back({S(0), S(0), S(0)});
  return cloud;
}

/// The definition, computed the slow way: every valid point's nearest lattice point by brute
/// force, minimum range per cell.
template <typename S>
std::vector<S> brute_force_descriptor(const terra::Lattice& lattice,
                                      const std::vector<Eigen::Matrix<S, 3, 1>>& cloud,
                                      double min_range) {
  std::vector<S> out(lattice.size(), S(0));
  for (const auto& p : cloud) {
    const ulc::Vec3d pd = p.template cast<double>();
    const double r = pd.norm();
    if (!std::isfinite(r) || r < min_range || r == 0.0) continue;
    const auto j = terra::brute_force_nearest(lattice.points(), pd / r);
    const S rs = static_cast<S>(r);
    if (out[j] == S(0) || rs < out[j]) out[j] = rs;
  }
  return out;
}

}  // namespace

TEMPLATE_TEST_CASE("descriptor keeps the minimum range per cell, as brute force does",
                   "[descriptor]", float, double) {
  const terra::Lattice lattice(2000);
  const auto cloud = random_cloud<TestType>(20000, 21);
  terra::DescriptorOptions options;
  options.min_range = 0.5;
  const auto f = terra::make_descriptor(lattice, cloud, options);
  const auto truth = brute_force_descriptor(lattice, cloud, options.min_range);
  REQUIRE(f.size() == lattice.size());
  std::size_t mismatches = 0;
  for (std::size_t j = 0; j < f.size(); ++j) mismatches += f.range[j] != truth[j];
  CHECK(mismatches == 0);
  CHECK(f.points_invalid == 2);  // NaN and infinity
  // Below min_range: ranges 0.1 .. 0.5 of the generator, and the zero point.
  std::size_t near = 1;
  for (const auto& p : cloud)
    if (std::isfinite(p.norm()) && p.template cast<double>().norm() < 0.5 && p.norm() > 0) ++near;
  CHECK(f.points_ignored == near);
  CHECK(f.points_used + f.points_ignored + f.points_invalid == cloud.size());
  for (const TestType r : f.range) CHECK((r == TestType(0) || r >= TestType(0.5)));
  // Most cells are hit by 22000 points on 2000 cells.
  CHECK(f.filled_cells() > 1900);
}

TEST_CASE("descriptor is the same for any cloud type and for the kd-tree lookup", "[descriptor]") {
  const terra::Lattice lattice(3000);
  const terra::KdTreeLookup kd(lattice);
  const auto scan = terra_test::scan(ulc::Mat3d::Identity());
  ulc::PointCloud<double> soa;
  Eigen::MatrixX3d mat(static_cast<Eigen::Index>(scan.size()), 3);
  ulc::traits::resize(soa, scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    ulc::traits::set_point(soa, i, scan[i]);
    mat.row(static_cast<Eigen::Index>(i)) = scan[i].transpose();
  }
  const auto a = terra::make_descriptor(lattice, scan);
  const auto b = terra::make_descriptor(lattice, soa);
  const auto c = terra::make_descriptor(lattice, mat);
  const auto d = terra::make_descriptor(kd, scan);
  CHECK(a.range == b.range);
  CHECK(a.range == c.range);
  CHECK(a.range == d.range);
  // The scene reaches well beyond d1 = 20 m: the distance has cells to work with.
  CHECK(a.cells_beyond(20.0) > a.filled_cells() / 5);
}

TEST_CASE("max_range drops far points and an empty lattice gives an empty descriptor",
          "[descriptor]") {
  const terra::Lattice lattice(500);
  const std::vector<Eigen::Vector3d> cloud = {{10, 0, 0}, {0, 50, 0}, {0, 0, 0.2}};
  terra::DescriptorOptions options;
  options.max_range = 20.0;
  const auto f = terra::make_descriptor(lattice, cloud, options);
  CHECK(f.points_used == 1);
  CHECK(f.points_ignored == 2);
  CHECK(f.filled_cells() == 1);
  CHECK(f.range[lattice.nearest(ulc::Vec3d(1, 0, 0))] == 10.0);
  const auto empty = terra::make_descriptor(terra::Lattice(), cloud);
  CHECK(empty.size() == 0);
}
