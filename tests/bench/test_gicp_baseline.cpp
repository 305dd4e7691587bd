// The GICP refinement baseline of bench_jeep (bench/gicp_baseline.hpp) on a synthetic room: two
// independent samplings of the same box (floor, ceiling, four walls) and a slanted panel, the
// source placed by a known pose. GICP must recover the pose from a small start and from the
// refinement table's 5 deg / 2 m one, give the same answer twice, and refuse too few points.
#include <catch2/catch.hpp>

#include <cstdint>
#include <random>

#include "../../bench/gicp_baseline.hpp"
#include "test_units.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/pose_error.hpp"

namespace {

using ulc::Isometry3d;
using ulc::Vec3d;
using ulc_test::kDeg;

/// A uniform number in [-1, 1) from the raw generator (the same on every standard library).
double jitter(std::mt19937& rng) {
  return static_cast<double>(rng() % 2000000) / 1e6 - 1.0;
}

/// Points on the rectangle origin + u * [0, |eu|] + v * [0, |ev|] every `step` metres, each
/// moved within the rectangle by up to 40 % of a step.
void sample_rectangle(const Vec3d& origin, const Vec3d& eu, const Vec3d& ev, double step,
                      std::mt19937& rng, std::vector<Vec3d>& out) {
  const int nu = static_cast<int>(eu.norm() / step), nv = static_cast<int>(ev.norm() / step);
  const Vec3d u = eu.normalized(), v = ev.normalized();
  for (int i = 0; i <= nu; ++i)
    for (int j = 0; j <= nv; ++j) {
      const double du = i + 0.4 * jitter(rng);  // two statements: a fixed order of draws
      const double dv = j + 0.4 * jitter(rng);
      out.push_back(origin + du * step * u + dv * step * v);
    }
}

/// A 10 x 8 x 3 m room around the origin and a panel leaning in a corner, sampled every 10 cm.
ulc::PointCloud<double> room(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Vec3d> p;
  const double h = 0.1;
  sample_rectangle({-5, -4, 0}, {10, 0, 0}, {0, 8, 0}, h, rng, p);       // floor
  sample_rectangle({-5, -4, 3}, {10, 0, 0}, {0, 8, 0}, h, rng, p);       // ceiling
  sample_rectangle({-5, -4, 0}, {10, 0, 0}, {0, 0, 3}, h, rng, p);       // wall y = -4
  sample_rectangle({-5, 4, 0}, {10, 0, 0}, {0, 0, 3}, h, rng, p);        // wall y = 4
  sample_rectangle({-5, -4, 0}, {0, 8, 0}, {0, 0, 3}, h, rng, p);        // wall x = -5
  sample_rectangle({5, -4, 0}, {0, 8, 0}, {0, 0, 3}, h, rng, p);         // wall x = 5
  sample_rectangle({2, 2, 0}, {1.5, 1.0, 0}, {0.5, 0.5, 2}, h, rng, p);  // slanted panel
  ulc::PointCloud<double> cloud;
  cloud.points.assign(p.begin(), p.end());
  return cloud;
}

ulc::PointCloud<double> moved(const ulc::PointCloud<double>& c, const Isometry3d& T) {
  ulc::PointCloud<double> out;
  for (const auto& p : c.points) out.points.push_back(T * p);
  return out;
}

Isometry3d pose(double deg, const Vec3d& axis, const Vec3d& t) {
  Isometry3d T = Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(deg * kDeg, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

/// The target room, and a second sampling of it in the source frame: T_target_source = truth.
struct Scene {
  Isometry3d truth = pose(4.0, {1, 2, 3}, {0.3, -0.2, 0.1});
  gicp_baseline::Points target = gicp_baseline::prepare(room(1), 0.25, 0.0, 1e9);
  gicp_baseline::Points source =
      gicp_baseline::prepare(moved(room(2), truth.inverse()), 0.25, 0.0, 1e9);
};

}  // namespace

TEST_CASE("GICP recovers a small pose between two samplings of a room", "[bench][gicp]") {
  const Scene s;
  const auto r = gicp_baseline::gicp(s.source, s.target, Isometry3d::Identity());
  const auto e = ulc::pose_error(s.truth, r.pose);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m, " << r.iterations
                << " iterations, " << r.correspondences << " matches");
  CHECK(r.converged);
  CHECK(e.rotation_deg < 0.05);
  CHECK(e.translation_m < 0.005);
  CHECK(r.correspondences > s.source.size() / 2);
}

TEST_CASE("GICP recovers the pose from the refinement table's 5 deg / 2 m start", "[bench][gicp]") {
  const Scene s;
  const Isometry3d start = pose(5.0, {-2, 1, 1}, {1.6, 1.0, 0.6}) * s.truth;
  REQUIRE(ulc::pose_error(s.truth, start).translation_m > 1.9);
  const auto r = gicp_baseline::gicp(s.source, s.target, start);
  const auto e = ulc::pose_error(s.truth, r.pose);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m, " << r.iterations
                << " iterations");
  CHECK(r.converged);
  CHECK(e.rotation_deg < 0.05);
  CHECK(e.translation_m < 0.005);
}

TEST_CASE("GICP gives the same pose twice", "[bench][gicp]") {
  const Scene s;
  const Isometry3d start = pose(2.0, {0, 0, 1}, {0.5, 0, 0});
  const auto a = gicp_baseline::gicp(s.source, s.target, start);
  const auto b = gicp_baseline::gicp(s.source, s.target, start);
  CHECK(a.pose.matrix() == b.pose.matrix());
  CHECK(a.iterations == b.iterations);
}

TEST_CASE("GICP refuses clouds with fewer points than the correspondences it needs",
          "[bench][gicp]") {
  const Scene s;
  const gicp_baseline::Points few(s.source.begin(), s.source.begin() + 10);
  const auto r = gicp_baseline::gicp(few, s.target, Isometry3d::Identity());
  CHECK_FALSE(r.converged);
  CHECK(r.iterations == 0);
}
