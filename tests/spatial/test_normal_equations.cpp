#include <tbb/task_arena.h>
#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "ulc/core/normal_equations.hpp"
#include "ulc/core/parallel_reduce.hpp"

TEST_CASE("NormalEquations6 equals dense J^T W J and J^T W r", "[normal_equations]") {
  constexpr int m = 200;
  std::mt19937 rng(111);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> uw(0.1, 2.0);
  Eigen::Matrix<double, m, 6> J;
  Eigen::Matrix<double, m, 1> r, w;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < 6; ++j) J(i, j) = g(rng);
    r[i] = g(rng);
    w[i] = uw(rng);
  }
  ulc::NormalEquations6 ne;
  for (int i = 0; i < m; ++i) {
    if (i % 2 == 0)
      ne.add(J.row(i), r[i], w[i]);  // as a 1x6 row
    else
      ne.add(ulc::Vec6d(J.row(i).transpose()), r[i], w[i]);  // as a 6-vector
  }
  const Eigen::Matrix<double, 6, 6> H = J.transpose() * w.asDiagonal() * J;
  const Eigen::Matrix<double, 6, 1> b = J.transpose() * w.asDiagonal() * r;
  CHECK(ne.count == m);
  CHECK((ne.H - H).norm() < 1e-10 * H.norm());
  CHECK((ne.b - b).norm() < 1e-10 * b.norm());
  CHECK(ne.cost == Approx(r.dot(w.asDiagonal() * r)));
  CHECK(ne.H == ne.H.transpose());

  // float Jacobians are promoted; weight defaults to 1.
  ulc::NormalEquations6 nf;
  const Eigen::Matrix<float, 1, 6> jf(1.f, 2.f, 3.f, 4.f, 5.f, 6.f);
  nf.add(jf, 0.5);
  CHECK(nf.H(5, 5) == 36.0);
  CHECK(nf.b[2] == 1.5);
  CHECK(nf.cost == 0.25);
}

TEST_CASE("NormalEquations6 joins: split sums add up, deterministically", "[normal_equations]") {
  constexpr std::size_t m = 5000;
  std::mt19937 rng(121);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<ulc::Vec6d> rows(m);
  std::vector<double> res(m);
  for (std::size_t i = 0; i < m; ++i) {
    for (int j = 0; j < 6; ++j) rows[i][j] = g(rng);
    res[i] = g(rng);
  }
  ulc::NormalEquations6 serial;
  for (std::size_t i = 0; i < m; ++i) serial.add(rows[i], res[i]);

  auto reduce = [&](int threads) {
    tbb::task_arena arena(threads);
    return arena.execute([&] {
      return ulc::deterministic_reduce(
          m, ulc::NormalEquations6{},
          [&](std::size_t b, std::size_t e, ulc::NormalEquations6 acc) {
            for (std::size_t i = b; i < e; ++i) acc.add(rows[i], res[i]);
            return acc;
          },
          [](const ulc::NormalEquations6& a, const ulc::NormalEquations6& b) { return a + b; },
          256);
    });
  };
  const auto one = reduce(1);
  const auto two = reduce(2);
  CHECK(one.count == m);
  CHECK((one.H - serial.H).norm() < 1e-9 * serial.H.norm());
  CHECK((one.b - serial.b).norm() < 1e-9 * serial.b.norm());
  CHECK(one.cost == Approx(serial.cost));
  CHECK(one.H == two.H);
  CHECK(one.b == two.b);
  CHECK(one.cost == two.cost);
}
