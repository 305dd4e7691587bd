// Chi-square, F and Hotelling's T^2 without a library (ulc/core/small_sample.hpp): quantiles
// against published tables, and the widening of a covariance estimated from few clusters
// against a Monte-Carlo of the sample mean, whose T^2 law is exact.
#include <catch2/catch.hpp>

#include <cstdint>
#include <random>

#include <Eigen/Cholesky>

#include "ulc/core/cluster_covariance.hpp"
#include "ulc/core/small_sample.hpp"

TEST_CASE("chi-square and F quantiles match the published tables", "[core][small_sample]") {
  CHECK(ulc::chi_square_quantile(0.95, 6) == Approx(12.592).epsilon(1e-4));
  CHECK(ulc::chi_square_quantile(0.99, 3) == Approx(11.345).epsilon(1e-4));
  CHECK(ulc::chi_square_quantile(0.9973, 6) == Approx(20.06).epsilon(1e-3));
  CHECK(ulc::f_quantile(0.99, 6, 20) == Approx(3.87).epsilon(2e-3));
  CHECK(ulc::f_quantile(0.95, 6, 20) == Approx(2.60).epsilon(2e-3));
  CHECK(ulc::f_quantile(0.95, 1, 1) == Approx(161.4).epsilon(1e-3));
  CHECK(ulc::f_quantile(0.95, 10, 60) == Approx(1.99).epsilon(3e-3));
}

TEST_CASE("the small-sample scale shrinks to 1 with many clusters and is undefined with too few",
          "[core][small_sample]") {
  CHECK_FALSE(ulc::small_sample_scale(6, 6.0));  // nu = 5 < p
  const double k25 = *ulc::small_sample_scale(6, 25.0);
  const double k100 = *ulc::small_sample_scale(6, 100.0);
  // T^2(6, 20) at 99 %: 6 * 20 / 15 * F(6, 15) = 8 * 4.32 (table), chi-square(6): 16.812.
  CHECK(*ulc::small_sample_scale(6, 21.0, 0.99) == Approx(8.0 * 4.32 / 16.812).epsilon(2e-3));
  CHECK(k25 > k100);
  CHECK(k100 > 1.0);
  CHECK(*ulc::small_sample_scale(6, 1e6) == Approx(1.0).epsilon(1e-3));
}

TEST_CASE("the widened covariance of a sample mean holds its ellipsoid's probability",
          "[core][small_sample]") {
  // The mean of G = 8 draws of N(0, I_3) with its sample covariance / G: d^2 is T^2(3, 7). The
  // chi-square 95 % ellipsoid of the plain estimate holds about 75 % of the truth; widened, 95 %.
  constexpr int kTrials = 6000;
  constexpr int kDraws = 8;
  const double level = 0.95;
  const double limit = ulc::chi_square_quantile(level, 3);
  const double k = *ulc::small_sample_scale(3, kDraws, level);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  int plain = 0, widened = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    Eigen::Matrix<double, 3, kDraws> x;
    for (int i = 0; i < x.size(); ++i) x.data()[i] = gauss(rng);
    const Eigen::Vector3d mean = x.rowwise().mean();
    const Eigen::Matrix<double, 3, kDraws> centred = x.colwise() - mean;
    const Eigen::Matrix3d S = centred * centred.transpose() / (kDraws - 1.0) / kDraws;
    const double d2 = mean.dot(S.ldlt().solve(mean));
    plain += d2 <= limit ? 1 : 0;
    widened += d2 <= k * limit ? 1 : 0;
  }
  CHECK(plain / double(kTrials) < 0.85);
  CHECK(widened / double(kTrials) == Approx(level).margin(0.012));
}

TEST_CASE("a jackknife's widened covariance is its covariance times the scale of its clusters",
          "[core][small_sample]") {
  ulc::ClusterJackknife<2, int> few, enough;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss;
  for (int c = 0; c < 12; ++c) {
    const Eigen::Vector2d g(gauss(rng), gauss(rng));
    if (c < 2) few.add(c, Eigen::Matrix2d::Identity(), g);
    enough.add(c, Eigen::Matrix2d::Identity(), g);
  }
  CHECK_FALSE(few.widened_covariance());  // G - 1 = 1 < 2 directions
  const auto plain = enough.covariance();
  const auto wide = enough.widened_covariance();
  REQUIRE(plain);
  REQUIRE(wide);
  CHECK(wide->isApprox(*ulc::small_sample_scale(2, 12.0) * *plain));
  // A marginal: the leading parameter's block of the two-parameter jackknife, widened as one
  // direction.
  const auto marginal = enough.widened_marginal<1, 2>();
  REQUIRE(marginal);
  CHECK((*marginal)(0, 0) == Approx(*ulc::small_sample_scale(1, 12.0) * (*plain)(0, 0)));
  // Two clusters estimate one direction (G - 1 = 1), so the marginal exists where the whole
  // two-parameter covariance does not.
  REQUIRE(few.widened_marginal<1, 2>());
  CHECK((*few.widened_marginal<1, 2>())(0, 0) ==
        Approx(*ulc::small_sample_scale(1, 2.0) * (*few.covariance())(0, 0)));
}
