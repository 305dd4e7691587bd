// Robust kernels: IRLS weights are rho'(r) / r (checked by central differences), known values,
// the shapes (convex Huber, redescending Cauchy and Geman-McClure), and what they are for: a
// redescending kernel ignores a block of false correspondences that least squares follows.
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "registration_test_util.hpp"
#include "ulc/core/point_to_plane.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/registration_target.hpp"
#include "ulc/core/robust_kernel.hpp"

using namespace reg_test;
using ulc::RobustKernel;

TEST_CASE("kernel weights are rho'(r) / r and lie in (0, 1]", "[registration][kernel]") {
  for (const RobustKernel& k : {RobustKernel::least_squares(), RobustKernel::huber(0.1),
                                RobustKernel::cauchy(0.2), RobustKernel::geman_mcclure(0.05)}) {
    INFO(ulc::to_string(k.type));
    CHECK(k.weight(0.0) == 1.0);
    CHECK(k.rho(0.0) == 0.0);
    for (double r = -1.0; r <= 1.0; r += 0.0137) {
      INFO("r = " << r);
      const double h = 1e-7;
      const double derivative = (k.rho(r + h) - k.rho(r - h)) / (2 * h);
      CHECK(k.weight(r) * r == Approx(derivative).margin(1e-7));
      CHECK(k.weight(r) > 0.0);
      CHECK(k.weight(r) <= 1.0);
      CHECK(k.weight(r) == k.weight(-r));
      CHECK(k.rho(r) == Approx(k.rho(-r)));
    }
  }
}

TEST_CASE("kernel weights have their textbook values and shapes", "[registration][kernel]") {
  const double k = 0.1;
  const RobustKernel huber = RobustKernel::huber(k), cauchy = RobustKernel::cauchy(k),
                     gm = RobustKernel::geman_mcclure(k);
  CHECK(huber.weight(0.5 * k) == 1.0);
  CHECK(huber.weight(k) == 1.0);
  CHECK(huber.weight(4 * k) == Approx(0.25));
  CHECK(cauchy.weight(k) == Approx(0.5));
  CHECK(gm.weight(k) == Approx(0.25));
  CHECK(gm.weight(3 * k) == Approx(0.01));
  // Influence psi(r) = w(r) r: Huber's saturates at k; the redescending ones fall back to 0.
  CHECK(huber.weight(10 * k) * 10 * k == Approx(k));
  CHECK(huber.weight(100 * k) * 100 * k == Approx(k));
  CHECK(cauchy.weight(100 * k) * 100 * k < 0.02 * k);
  CHECK(gm.weight(100 * k) * 100 * k < 1e-5 * k);
  // Least squares: weight 1 everywhere; a kernel without a valid scale acts as least squares.
  CHECK(RobustKernel::least_squares().weight(1e3) == 1.0);
  CHECK(RobustKernel::geman_mcclure(0.0).weight(1e3) == 1.0);
  CHECK(RobustKernel::huber(std::nan("")).rho(2.0) == 2.0);
}

TEST_CASE("a redescending kernel ignores a block of false matches that least squares follows",
          "[registration][kernel]") {
  // The source has a second copy of the north wall, 30 cm in front of the real one (a parked
  // bus the target never saw). Least squares splits the difference; Geman-McClure does not.
  const auto scene = courtyard(1, 3000, 0.005);
  auto source_points = courtyard(2, 3000, 0.005);
  std::mt19937_64 rng(3);
  sample_rectangle(source_points, rng, Vec3d(-15, 11.7, 0), Vec3d::UnitX(), Vec3d::UnitZ(), 30, 6,
                   3000, 0.005);
  const ulc::PlaneCloud<double> target(to_cloud<double>(scene));
  const auto source = to_cloud<double>(source_points);
  ulc::RegistrationOptions o;
  o.max_correspondence_distance = 0.5;
  o.kernel = RobustKernel::least_squares();
  const auto ls = ulc::register_point_to_plane(source, target, Isometry3d::Identity(), o);
  o.kernel = RobustKernel::geman_mcclure(0.05);
  const auto gm = ulc::register_point_to_plane(source, target, Isometry3d::Identity(), o);
  const auto e_ls = ulc::pose_error(Isometry3d::Identity(), ls.pose);
  const auto e_gm = ulc::pose_error(Isometry3d::Identity(), gm.pose);
  INFO("least squares " << e_ls.translation_m << " m, Geman-McClure " << e_gm.translation_m);
  CHECK(e_ls.translation_m > 0.03);
  CHECK(e_gm.translation_m < 0.002);
}
