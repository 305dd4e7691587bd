// The two-way calibration phase (jeep/two_way.hpp): its midpoint is inverse-consistent, and
// single-frame JEEP run with base and target swapped gives the inverse extrinsic.
#include <catch2/catch.hpp>
#include <random>

#include "jeep/jeep.hpp"
#include "jeep/two_way.hpp"
#include "jeep_test_util.hpp"
#include "ulc/core/pose_error.hpp"

using namespace jeep_test;

namespace {

Isometry3d random_pose(std::mt19937_64& rng, double angle, double distance) {
  return disturbed(Isometry3d::Identity(), rng, angle, distance);
}

double translation_gap(const Isometry3d& X, const Isometry3d& Y) {
  return (X.inverse() * Y).translation().norm();
}

double rotation_gap(const Isometry3d& X, const Isometry3d& Y) {
  return ulc::so3_log(Isometry3d(X.inverse() * Y).linear()).norm();
}

/// One frame of each LiDAR of a parked 64-32 rig (a moving one would need deskewing, which a
/// single frame cannot give).
struct ParkedRig {
  std::vector<ulc::PointCloud<float>> a, b;
  std::vector<double> time_a, time_b;
  Isometry3d truth = Isometry3d::Identity();
};

ParkedRig parked_rig() {
  const auto d = parked_64_32();
  ParkedRig r;
  r.a = {d.lidars.at(0).frames.at(0)};
  r.b = {d.lidars.at(1).frames.at(0)};
  r.time_a = {d.lidars[0].timestamps.at(0)};
  r.time_b = {d.lidars[1].timestamps.at(0)};
  r.truth = d.pairs.at(0).T_base_target;
  return r;
}

}  // namespace

TEST_CASE("se3_midpoint is symmetric, inverse-consistent and halfway", "[jeep][two_way]") {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Isometry3d X = random_pose(rng, 170.0 * kDeg, 20.0);
    const Isometry3d Y = X * random_pose(rng, 30.0 * kDeg, 2.0);
    const Isometry3d M = jeep::se3_midpoint(X, Y);
    CHECK(jeep::se3_midpoint(Y, X).isApprox(M, 1e-9));
    const Isometry3d M_inv = jeep::se3_midpoint(Isometry3d(X.inverse()), Isometry3d(Y.inverse()));
    CHECK(M_inv.isApprox(Isometry3d(M.inverse()), 1e-9));
    // Halfway along the geodesic: the same step from X to M as from M to Y.
    const ulc::Vec6d first = ulc::se3_log(Isometry3d(X.inverse() * M));
    const ulc::Vec6d second = ulc::se3_log(Isometry3d(M.inverse() * Y));
    CHECK((first - second).norm() < 1e-9);
    CHECK(jeep::se3_midpoint(X, X).isApprox(X, 1e-12));
  }
}

TEST_CASE("single-frame JEEP with base and target swapped gives the inverse", "[jeep][two_way]") {
  const ParkedRig rig = parked_rig();
  std::mt19937_64 rng(11);
  const Isometry3d initial = disturbed(rig.truth, rng, 2.0 * kDeg, 0.5);
  const jeep::JeepOptions options;
  const auto forward = jeep::run_jeep(rig.a, rig.time_a, rig.b, rig.time_b, initial, options);
  const auto swapped =
      jeep::run_jeep(rig.b, rig.time_b, rig.a, rig.time_a, Isometry3d(initial.inverse()), options);
  INFO("forward: " << forward.reason << "; swapped: " << swapped.reason);
  REQUIRE(forward.ok());
  REQUIRE(swapped.ok());
  REQUIRE(forward.two_way.applied);
  REQUIRE(swapped.two_way.applied);
  const auto e = ulc::pose_error(rig.truth, forward.extrinsic);
  const double gap_t = forward.two_way.gap_translation, gap_r = forward.two_way.gap_rotation;
  const Isometry3d cycle = forward.extrinsic * swapped.extrinsic;
  const double cycle_t = translation_gap(Isometry3d::Identity(), cycle);
  const double cycle_r = rotation_gap(Isometry3d::Identity(), cycle);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m; directions "
                << gap_t << " m, " << gap_r / kDeg << " deg apart; swap cycle " << cycle_t << " m, "
                << cycle_r / kDeg << " deg");
  CHECK(e.rotation_deg < 0.1);
  CHECK(e.translation_m < 0.02);
  // Both runs find the same two minima and meet at inverse points: the cycle is the
  // registration tolerances (1e-4 m, 1e-5 rad), not the directions' gap a one-way answer
  // would leave. The rig accuracy bar is 0.02 deg and 5 mm.
  CHECK(cycle_t < 0.005);
  CHECK(cycle_r < 0.02 * kDeg);
  CHECK(cycle_t < 0.25 * gap_t + 3e-4);
  CHECK(cycle_r < 0.25 * gap_r + 3e-5);
  // The disagreement is a property of the data, the same whichever LiDAR is the base.
  CHECK(swapped.two_way.gap_translation == Approx(gap_t).margin(3e-4));
}

TEST_CASE("the two-way step can be switched off", "[jeep][two_way]") {
  const ParkedRig rig = parked_rig();
  jeep::JeepOptions options;
  options.two_way = false;
  const auto r = jeep::run_jeep(rig.a, rig.time_a, rig.b, rig.time_b, rig.truth, options);
  REQUIRE(r.ok());
  CHECK_FALSE(r.two_way.applied);
  CHECK(r.two_way.gap_translation == 0.0);
}
