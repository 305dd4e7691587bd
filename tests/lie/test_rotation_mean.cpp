// Chordal and Karcher means of rotations.
#include <catch2/catch.hpp>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "lie_test_support.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/rotation_mean.hpp"

using lie_test::max_diff;
using lie_test::Tol;

namespace {

template <typename S>
using Rotations = std::vector<ulc::Mat3<S>>;

// centre * exp(+-d_i): noise symmetric about the centre, so both means are exactly the centre.
template <typename S>
Rotations<S> symmetric_scatter(std::mt19937& rng, const Eigen::Matrix3d& centre, int pairs,
                               double spread) {
  Rotations<S> out;
  for (int i = 0; i < pairs; ++i) {
    const Eigen::Vector3d d = lie_test::uniform(rng, 0.0, spread) * lie_test::random_axis(rng);
    out.push_back((centre * ulc::so3_exp(d)).cast<S>());
    out.push_back((centre * ulc::so3_exp(Eigen::Vector3d(-d))).cast<S>());
  }
  return out;
}

template <typename S>
Rotations<S> random_scatter(std::mt19937& rng, const Eigen::Matrix3d& centre, int n,
                            double spread) {
  Rotations<S> out;
  for (int i = 0; i < n; ++i)
    out.push_back((centre * ulc::so3_exp(Eigen::Vector3d(lie_test::uniform(rng, 0.0, spread) *
                                                         lie_test::random_axis(rng))))
                      .cast<S>());
  return out;
}

// Sum over i of w_i ||M - R_i||_F^2 (chordal cost) and of w_i angle(M, R_i)^2 (geodesic cost).
template <typename S>
double chordal_cost(const ulc::Mat3<S>& M, const Rotations<S>& Rs, const std::vector<S>& w) {
  double c = 0;
  for (std::size_t i = 0; i < Rs.size(); ++i)
    c += double(w[i]) * (M.template cast<double>() - Rs[i].template cast<double>()).squaredNorm();
  return c;
}
template <typename S>
double geodesic_cost(const ulc::Mat3<S>& M, const Rotations<S>& Rs, const std::vector<S>& w) {
  double c = 0;
  for (std::size_t i = 0; i < Rs.size(); ++i) {
    const double a = ulc::rotation_error_rad(M.template cast<double>().eval(),
                                             Rs[i].template cast<double>().eval());
    c += double(w[i]) * a * a;
  }
  return c;
}

}  // namespace

TEMPLATE_TEST_CASE("both means recover the centre of symmetric noise", "[lie][mean]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(51);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Matrix3d centre = lie_test::random_rotation(rng);
    const Rotations<S> Rs = symmetric_scatter<S>(rng, centre, 20, 0.5);
    const auto chordal = ulc::chordal_mean(Rs);
    REQUIRE(chordal.ok);
    CHECK(max_diff(chordal.rotation, centre) < 20 * Tol<S>::exact);
    const auto karcher = ulc::karcher_mean(Rs);
    REQUIRE(karcher.ok);
    CHECK(karcher.converged);
    CHECK(karcher.iterations >= 1);
    CHECK(max_diff(karcher.rotation, centre) < 20 * Tol<S>::exact);
  }
}

TEMPLATE_TEST_CASE("means of asymmetric scatter minimise their own costs", "[lie][mean]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(52);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Matrix3d centre = lie_test::random_rotation(rng);
    const Rotations<S> Rs = random_scatter<S>(rng, centre, 15, 0.8);
    std::vector<S> w;
    for (std::size_t i = 0; i < Rs.size(); ++i) w.push_back(S(lie_test::uniform(rng, 0.2, 2.0)));

    const auto karcher = ulc::karcher_mean(Rs, w);
    REQUIRE(karcher.ok);
    REQUIRE(karcher.converged);
    // First-order optimality of the geodesic mean: the weighted logs sum to zero.
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < Rs.size(); ++i)
      sum +=
          double(w[i]) *
          ulc::so3_log(ulc::Mat3<S>(karcher.rotation.transpose() * Rs[i])).template cast<double>();
    CHECK(sum.norm() < 100 * Tol<S>::exact);

    // Brute force: no nearby rotation has a lower cost than the respective mean.
    const auto chordal = ulc::chordal_mean(Rs, w);
    REQUIRE(chordal.ok);
    const double c_chordal = chordal_cost(chordal.rotation, Rs, w);
    const double c_karcher = geodesic_cost(karcher.rotation, Rs, w);
    for (int k = 0; k < 50; ++k) {
      const ulc::Vec3<S> d = (1e-2 * lie_test::random_axis(rng)).cast<S>();
      const ulc::Mat3<S> step = ulc::so3_exp(d);
      CHECK(chordal_cost(ulc::Mat3<S>(chordal.rotation * step), Rs, w) > c_chordal);
      CHECK(geodesic_cost(ulc::Mat3<S>(karcher.rotation * step), Rs, w) > c_karcher);
    }
  }
}

TEMPLATE_TEST_CASE("weights act like repetition and a zero weight drops a rotation", "[lie][mean]",
                   float, double) {
  using S = TestType;
  std::mt19937 rng(53);
  const Rotations<S> Rs = random_scatter<S>(rng, lie_test::random_rotation(rng), 4, 0.6);
  const Rotations<S> repeated = {Rs[0], Rs[0], Rs[0], Rs[1], Rs[2], Rs[2]};
  const std::vector<S> w = {S(3), S(1), S(2), S(0)};
  CHECK(max_diff(ulc::chordal_mean(Rs, w).rotation, ulc::chordal_mean(repeated).rotation) <
        20 * Tol<S>::exact);
  CHECK(max_diff(ulc::karcher_mean(Rs, w).rotation, ulc::karcher_mean(repeated).rotation) <
        20 * Tol<S>::exact);
  // A single rotation is its own mean.
  const auto single = ulc::karcher_mean(Rotations<S>{Rs[3]});
  CHECK(single.converged);
  CHECK(max_diff(single.rotation, Rs[3]) < 10 * Tol<S>::exact);
}

TEMPLATE_TEST_CASE("unusable inputs give a reason instead of a mean", "[lie][mean]", float,
                   double) {
  using S = TestType;
  const Rotations<S> none;
  const Rotations<S> two = {ulc::Mat3<S>::Identity(), ulc::Mat3<S>::Identity()};
  const auto empty = ulc::chordal_mean(none);
  CHECK_FALSE(empty.ok);
  CHECK(std::string(empty.reason).find("no rotations") != std::string::npos);
  CHECK_FALSE(ulc::karcher_mean(none).ok);
  CHECK_FALSE(ulc::karcher_mean(none).converged);
  CHECK_FALSE(ulc::chordal_mean(two, std::vector<S>{S(1)}).ok);
  CHECK_FALSE(ulc::karcher_mean(two, std::vector<S>{S(1), S(-1)}).ok);
  CHECK_FALSE(ulc::chordal_mean(two, std::vector<S>{S(0), S(0)}).ok);
  CHECK_FALSE(ulc::chordal_mean(two, std::vector<S>{S(1), std::numeric_limits<S>::infinity()}).ok);
  const auto fine = ulc::karcher_mean(two, std::vector<S>{S(0), S(1)});
  CHECK(fine.ok);
  CHECK(std::string(fine.reason).empty());
  // No iterations allowed: the chordal start, not claimed as converged.
  const auto capped = ulc::karcher_mean(two, 0);
  CHECK(capped.ok);
  CHECK_FALSE(capped.converged);
  CHECK(capped.iterations == 0);
}
