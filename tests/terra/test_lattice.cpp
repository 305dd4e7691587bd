#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "terra/kdtree_lookup.hpp"
#include "terra/lattice.hpp"
#include "terra_test_util.hpp"

using terra_test::kPi;

namespace {

std::vector<terra::LatticeIndex> brute_force_all(const std::vector<ulc::Vec3d>& points,
                                                 const std::vector<ulc::Vec3d>& queries) {
  std::vector<terra::LatticeIndex> out(queries.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 256), [&](const auto& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i)
      out[i] = terra::brute_force_nearest(points, queries[i]);
  });
  return out;
}

}  // namespace

TEST_CASE("Fibonacci lattice follows Algorithm 1", "[lattice]") {
  for (std::size_t n : {2u, 3u, 100u, 10000u}) {
    const auto pts = terra::fibonacci_lattice(n);
    REQUIRE(pts.size() == n);
    const double golden = (std::sqrt(5.0) + 1.0) / 2.0;
    for (std::size_t i = 0; i < n; ++i) {
      INFO("n = " << n << ", i = " << i);
      CHECK(std::fabs(pts[i].norm() - 1.0) < 1e-12);
      const double y = 1.0 - 2.0 * double(i) / double(n - 1);
      CHECK(pts[i].y() == y);
      const double theta = 2.0 * kPi * double(i) / golden;
      if (i == 0 || i == n - 1) continue;  // the poles have no azimuth
      CHECK(std::atan2(pts[i].z(), pts[i].x()) ==
            Approx(std::remainder(theta, 2.0 * kPi)).margin(1e-9));
    }
    CHECK(pts.front().y() == 1.0);
    CHECK(pts.back().y() == -1.0);
  }
  CHECK(terra::fibonacci_lattice(1).empty());
  CHECK(terra::fibonacci_lattice(0).empty());
  CHECK(terra::Lattice(1).empty());
}

TEST_CASE("Fibonacci lattice is near-uniform", "[lattice]") {
  const std::size_t n = 3000;
  const terra::Lattice lattice(n);
  const auto& pts = lattice.points();
  // Nearest-neighbour spacing: every point has a neighbour at a similar distance.
  std::vector<double> nn(n, 10.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      if (i != j) nn[i] = std::min(nn[i], terra::angle_between(pts[i], pts[j]));
  const auto [lo, hi] = std::minmax_element(nn.begin(), nn.end());
  const double spacing = terra::lattice_spacing_rad(n);
  INFO("nn spacing min " << *lo / spacing << ", max " << *hi / spacing << " x mean spacing");
  // Algorithm 1 puts points exactly on both poles: the two pole pairs (0, 1) and (n-2, n-1)
  // sit at 0.56 of the spacing, every other point between 0.79 and 1.0 of it.
  CHECK(*lo / *hi > 0.55);
  const auto [inner_lo, inner_hi] = std::minmax_element(nn.begin() + 3, nn.end() - 3);
  CHECK(*inner_lo / *inner_hi > 0.85);
  CHECK(*inner_lo > 0.85 * spacing);
  CHECK(*hi < 1.05 * spacing);

  // Equal areas: uniform random directions fall about equally into the Voronoi cells.
  const std::size_t samples = 300000;
  const auto dirs = terra_test::random_directions(samples, 11);
  std::vector<std::size_t> count(n, 0);
  for (const auto& d : dirs) ++count[lattice.nearest(d)];
  const double expected = double(samples) / double(n);
  double chi2 = 0;
  for (const std::size_t c : count)
    chi2 += (double(c) - expected) * (double(c) - expected) / expected;
  const double per_dof = chi2 / double(n - 1);
  INFO("chi-square per degree of freedom: " << per_dof);
  // Equal areas and Poisson counts give ~1; a 10% spread of cell areas would add ~1 more.
  CHECK(per_dof < 1.3);
}

TEST_CASE("cube-map and kd-tree lookups equal brute force", "[lattice]") {
  const std::size_t n = 10000;
  const terra::Lattice lattice(n);
  const terra::KdTreeLookup kd(lattice);
  INFO("cells per edge " << lattice.grid().cells_per_edge() << ", mean candidates "
                         << lattice.mean_candidates());
  std::vector<ulc::Vec3d> queries = terra_test::random_directions(100000, 5);
  // Adversarial directions: the lattice points, midpoints between neighbours (near-ties), and
  // the cube-map cell corners and face edges.
  for (std::size_t i = 0; i + 1 < n; i += 7) {
    queries.push_back(lattice.point(i));
    queries.push_back((lattice.point(i) + lattice.point(i + 1)).normalized());
  }
  for (std::size_t cell = 0; cell < lattice.grid().cell_count(); cell += 97)
    for (const auto& c : lattice.grid().corners(cell)) queries.push_back(c);
  for (double t = -1.0; t <= 1.0; t += 0.01) {
    queries.push_back(ulc::Vec3d(1, 1, t).normalized());
    queries.push_back(ulc::Vec3d(-1, t, 1).normalized());
    queries.push_back(ulc::Vec3d(t, -1, -1).normalized());
  }
  const auto truth = brute_force_all(lattice.points(), queries);
  std::vector<terra::LatticeIndex> batch(queries.size());
  lattice.nearest_batch(queries.data(), queries.size(), batch.data());
  std::size_t cube_mismatch = 0, batch_mismatch = 0, kd_mismatch = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    cube_mismatch += lattice.nearest(queries[i]) != truth[i];
    batch_mismatch += batch[i] != truth[i];
    kd_mismatch += kd.nearest(queries[i]) != truth[i];
  }
  CHECK(cube_mismatch == 0);
  CHECK(batch_mismatch == 0);
  CHECK(kd_mismatch == 0);
  CHECK(lattice.mean_candidates() < 2.0);  // the table mostly answers with one read
}

TEST_CASE("lookups are exact for tiny and odd lattice sizes", "[lattice]") {
  for (std::size_t n : {2u, 3u, 5u, 17u, 100u, 1001u}) {
    for (double fraction : {0.125, 0.5, 2.0}) {
      terra::LatticeOptions options;
      options.cell_fraction = fraction;
      const terra::Lattice lattice(n, options);
      const auto queries = terra_test::random_directions(5000, 7 + n);
      std::size_t mismatch = 0;
      for (const auto& q : queries)
        mismatch += lattice.nearest(q) != terra::brute_force_nearest(lattice.points(), q);
      INFO("n = " << n << ", cell fraction " << fraction);
      CHECK(mismatch == 0);
    }
  }
}
