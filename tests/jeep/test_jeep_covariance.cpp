// A static single-frame result ends at JEEP (HOTS skips itself: no motion) and carries JEEP's
// covariance: symmetric positive definite, with the error against the simulator's mounting
// inside its 3-sigma ellipsoid (chi-square with 6 dof at 99.73 %: bench_covariance --parked
// measures the coverage over seeds).
#include <catch2/catch.hpp>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "jeep_test_util.hpp"
#include "pipeline/calibrate.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"

using namespace jeep_test;

TEST_CASE("a parked rig's single frames give a JEEP result with an honest covariance",
          "[jeep][covariance]") {
  const auto parked = parked_64_32();
  const auto& a = parked.lidars[0];
  const auto& b = parked.lidars[1];
  REQUIRE(a.frames.size() == 1);
  const Isometry3d truth = parked.pairs[0].T_base_target;
  const ulc::CalibrateOptions o;  // the default stages: TERRA, JEEP, HOTS (skipped)
  const auto r = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
  INFO(ulc::to_string(r.status) << ": " << r.reason);
  REQUIRE(r.success);
  REQUIRE(r.hots);
  CHECK(r.hots->run == ulc::HotsRun::skipped);
  REQUIRE(r.covariance_6x6);
  const ulc::Mat6d& C = *r.covariance_6x6;
  CHECK(C.allFinite());
  CHECK((C - C.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * C.cwiseAbs().maxCoeff());
  CHECK(Eigen::SelfAdjointEigenSolver<ulc::Mat6d>(C).eigenvalues().minCoeff() > 0.0);
  const Vec6d xi = ulc::se3_log(Isometry3d(truth * r.T_base_target.inverse()));
  const double d2 = xi.dot(C.ldlt().solve(xi));
  const auto e = ulc::pose_error(truth, r.T_base_target);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m, sigmas "
                << C.diagonal().cwiseSqrt().transpose() << ", d^2 " << d2);
  CHECK(d2 <= 20.06);
  // Not inflated: the sigmas are below a millimetre-scale error's ten times.
  CHECK(std::sqrt(C.topLeftCorner<3, 3>().trace()) < 10.0 * std::max(e.translation_m, 1e-3));
}
