// Time synchronisation: synthetic trajectories of a rig with a known clock offset; the offset
// and the extrinsic come back, with and without pose noise, for float and double poses.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "hots/time_sync.hpp"
#include "hots_test_util.hpp"
#include "ulc/core/pose_error.hpp"

using namespace hots;
using namespace hots_test;

namespace {

/// T_world_vehicle(t): a drive with changing speed and heading, a little pitch and roll.
Isometry3d vehicle(double t) {
  const double x = 10 * t + 3 * std::sin(0.6 * t), y = 8 * std::sin(0.3 * t);
  const double dx = 10 + 1.8 * std::cos(0.6 * t), dy = 2.4 * std::cos(0.3 * t);
  Isometry3d T = Isometry3d::Identity();
  T.translation() = Vec3d(x, y, 0.3 * std::sin(0.2 * t));
  T.linear() = ulc::rotation_from_rpy(0.01 * std::sin(1.3 * t), 0.015 * std::sin(0.9 * t),
                                      std::atan2(dy, dx));
  return T;
}

/// Straight at constant speed: body velocity constant, so a clock offset is unobservable.
Isometry3d cruise(double t) {
  Isometry3d T = Isometry3d::Identity();
  T.translation() = Vec3d(10 * t, 0, 0);
  return T;
}

struct Rig {
  Isometry3d A, B;  ///< T_vehicle_a, T_vehicle_b
  std::vector<double> times_a, times_b;
  std::vector<Isometry3d> poses_a, poses_b;
  Isometry3d C() const { return A.inverse() * B; }
};

/// 10 Hz frames over `seconds` (pose noise in each sensor's own frame); b's clock lags: t_b =
/// t_true - offset (so t_a = t_b + offset).
Rig rig(double offset, double seconds, double noise_t, double noise_r, std::uint64_t seed,
        Isometry3d (*motion)(double) = vehicle) {
  Rig r;
  r.A = Isometry3d::Identity();
  r.A.translation() = Vec3d(1.3, 0.0, 2.0);
  r.A.linear() = ulc::rotation_from_rpy(0.01, -0.01, 0.02);
  r.B = Isometry3d::Identity();
  r.B.translation() = Vec3d(0.35, 0.55, 1.78);
  r.B.linear() = ulc::rotation_from_rpy(0.03, -0.05, 0.66);
  std::mt19937_64 rng(seed);
  const auto frames = static_cast<std::size_t>(seconds * 10);
  for (std::size_t k = 0; k < frames; ++k) {
    const double ta = 1.0 + 0.1 * static_cast<double>(k);
    const double sb = 1.037 + 0.1 * static_cast<double>(k);  // b's true firing time
    r.times_a.push_back(ta);
    r.poses_a.push_back(motion(ta) * r.A * ulc::se3_exp(random_vector6(rng, noise_t, noise_r)));
    r.times_b.push_back(sb - offset);
    r.poses_b.push_back(motion(sb) * r.B * ulc::se3_exp(random_vector6(rng, noise_t, noise_r)));
  }
  return r;
}

}  // namespace

TEST_CASE("time sync recovers a 50 ms clock offset and the extrinsic", "[hots][time_sync]") {
  const Rig r = rig(0.05, 20.0, 0.0, 0.0, 1);
  const TimeSyncResult s = time_sync(r.times_a, r.poses_a, r.times_b, r.poses_b);
  INFO(to_string(s.status) << ": " << s.reason);
  REQUIRE(s.ok());
  CHECK(s.time_offset_s == Approx(0.05).margin(0.002));
  const auto e = ulc::pose_error(r.C(), s.extrinsic);
  CHECK(e.translation_m < 0.005);
  CHECK(e.rotation_deg < 0.02);
  // The offset explains the spread: at zero offset the per-pair extrinsics scatter far more.
  CHECK(s.spread < 0.01 * s.spread_at_centre);
  CHECK(s.pairs > 150);
  CHECK(s.curve.size() == 41);
}

TEST_CASE("time sync finds no offset where there is none", "[hots][time_sync]") {
  const Rig r = rig(0.0, 20.0, 0.0, 0.0, 2);
  const TimeSyncResult s = time_sync(r.times_a, r.poses_a, r.times_b, r.poses_b);
  REQUIRE(s.ok());
  CHECK(std::abs(s.time_offset_s) < 0.002);
}

TEST_CASE("time sync with noisy poses, and with float poses", "[hots][time_sync]") {
  for (const double offset : {-0.03, 0.05}) {
    const Rig r = rig(offset, 30.0, 0.002, 0.02 * kDeg, 3);
    const TimeSyncResult s = time_sync(r.times_a, r.poses_a, r.times_b, r.poses_b);
    REQUIRE(s.ok());
    CHECK(s.time_offset_s == Approx(offset).margin(0.002));
    // The spread's covariance sees the simulated pose noise (two poses, 2 mm each axis).
    CHECK(std::sqrt(s.covariance(0, 0)) == Approx(0.002 * std::sqrt(2.0)).epsilon(0.5));
    std::vector<ulc::Isometry3<float>> fa, fb;
    for (const auto& T : r.poses_a) fa.push_back(T.cast<float>());
    for (const auto& T : r.poses_b) fb.push_back(T.cast<float>());
    const TimeSyncResult sf = time_sync(r.times_a, fa, r.times_b, fb);
    REQUIRE(sf.ok());
    CHECK(sf.time_offset_s == Approx(offset).margin(0.002));
  }
}

TEST_CASE("time sync reports unusable input", "[hots][time_sync]") {
  const Rig r = rig(0.0, 2.0, 0.0, 0.0, 4);
  std::vector<double> short_times(r.times_a.begin(), r.times_a.begin() + 1);
  std::vector<Isometry3d> short_poses(r.poses_a.begin(), r.poses_a.begin() + 1);
  CHECK(time_sync(short_times, short_poses, r.times_b, r.poses_b).status ==
        TimeSyncStatus::invalid_input);
  TimeSyncOptions o;
  o.min_pairs = 100;  // 2 s hold only 20 frames
  CHECK(time_sync(r.times_a, r.poses_a, r.times_b, r.poses_b, o).status ==
        TimeSyncStatus::too_few_pairs);
  auto unordered = r.times_b;
  std::swap(unordered[3], unordered[4]);
  CHECK(time_sync(r.times_a, r.poses_a, unordered, r.poses_b).status ==
        TimeSyncStatus::invalid_input);
}

TEST_CASE("time sync keeps the centre offset when the drive cannot tell", "[hots][time_sync]") {
  const Rig r = rig(0.05, 20.0, 0.002, 0.02 * kDeg, 5, cruise);
  const TimeSyncResult s = time_sync(r.times_a, r.poses_a, r.times_b, r.poses_b);
  REQUIRE(s.ok());
  CHECK_FALSE(s.significant);
  CHECK(s.time_offset_s == 0.0);
  // The same drive with turns and speed changes is significant.
  const Rig turning = rig(0.05, 20.0, 0.002, 0.02 * kDeg, 5);
  CHECK(time_sync(turning.times_a, turning.poses_a, turning.times_b, turning.poses_b).significant);
}
