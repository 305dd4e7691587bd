// The ground truth is right: target points moved by T_base_target land on the base's surfaces
// (static vehicle), and with the vehicle moving, points deskewed with the published trajectory,
// frame timestamps, per-point times and clock offset land on each other too.
#include <catch2/catch.hpp>
#include <cmath>

#include "sim_test_util.hpp"
#include "ulc/sim/simulate.hpp"

using namespace ulc::sim;
using sim_test::median;
using sim_test::quantile;
using ulc::Isometry3d;
using ulc::Vec3d;

namespace {

ulc::PointCloud<double> to_double(const ulc::PointCloud<float>& c, double max_range) {
  ulc::PointCloud<double> out;
  for (const auto& p : c.points)
    if (p.norm() <= max_range) out.points.push_back(p.cast<double>());
  return out;
}

std::vector<Vec3d> moved(const ulc::PointCloud<float>& c, const Isometry3d& T, double max_range) {
  std::vector<Vec3d> out;
  for (const auto& p : c.points)
    if (p.norm() > 1.5 && p.norm() <= max_range) out.push_back(T * p.cast<double>());
  return out;
}

}  // namespace

TEST_CASE("static 64-32: target points moved by T_base_target lie on the base's planes",
          "[sim][ground_truth]") {
  SimulationOptions o;
  o.seconds = 0.1;  // one frame each
  o.seed = 11;
  o.static_at_s = 12.0;
  const SimulationResult r = simulate(*scenario("64-32"), o);
  REQUIRE(r.ok());
  const Dataset& d = r.dataset;
  const LidarRecording& base = d.lidars[0];
  const LidarRecording& target = d.lidars[1];
  REQUIRE(base.frames.size() == 1);
  REQUIRE(target.frames.size() == 1);
  CHECK(base.frames[0].size() > 50000);
  CHECK(target.frames[0].size() > 20000);

  const double range_noise = 0.03;  // the larger of the two models' sigma (VLP-32C)
  const sim_test::PlaneReference ref(to_double(base.frames[0], 40.0), Vec3d::Zero());
  const Isometry3d T = d.pairs[0].T_base_target;
  const std::vector<double> res = ref.residuals(moved(target.frames[0], T, 40.0), 0.3, 0.6);
  INFO("median " << median(res) << " over " << res.size());
  CHECK(res.size() > 5000);  // a real overlap
  CHECK(median(res) < 3.0 * range_noise);
  CHECK(median(res) < 0.04);  // in fact close to the noise itself

  // The test can fail: a 2 degree, 10 cm error in the extrinsic is clearly visible.
  Isometry3d wrong = T;
  wrong.linear() =
      Eigen::AngleAxisd(2.0 * M_PI / 180, Vec3d(0.3, 0.2, 1).normalized()) * T.linear();
  wrong.translation() += Vec3d(0.1, 0.0, 0.0);
  const std::vector<double> bad = ref.residuals(moved(target.frames[0], wrong, 40.0), 0.3, 0.6);
  INFO("wrong extrinsic: median " << median(bad));
  CHECK(median(bad) > 2.0 * median(res));
}

TEST_CASE("moving, with a 50 ms clock offset: deskewed frames agree through the published truth",
          "[sim][ground_truth]") {
  SimulationOptions o;
  o.seconds = 1.0;
  o.seed = 4;
  const SimulationResult r = simulate(*scenario("offset-50ms"), o);
  REQUIRE(r.ok());
  const Dataset& d = r.dataset;
  const LidarRecording& base = d.lidars[0];
  const LidarRecording& target = d.lidars[1];
  const PairTruth& pair = d.pairs[0];
  REQUIRE(pair.time_offset_s == Approx(0.05));
  REQUIRE(base.clock_offset_s == 0.0);  // base clock = trajectory time

  // Base frame 5 deskewed into the world is the reference.
  const std::size_t kb = 5;
  const std::vector<Vec3d> base_world = sim_test::deskew(
      base.frames[kb], base.timestamps[kb], base.T_vehicle_lidar, d.trajectory, 1.5, 40.0);
  const sim_test::PlaneReference ref(sim_test::to_double(base_world),
                                     sim_test::sampled_pose(d.trajectory, base.timestamps[kb]) *
                                         base.T_vehicle_lidar.translation());
  // The target frame that overlaps it in time, converted with the pair truth only:
  // t_base = t_target + time_offset_s, and T_vehicle_target = T_vehicle_base T_base_target.
  std::size_t kt = 0;
  for (std::size_t k = 0; k < target.timestamps.size(); ++k)
    if (std::abs(target.timestamps[k] + pair.time_offset_s - base.timestamps[kb]) <
        std::abs(target.timestamps[kt] + pair.time_offset_s - base.timestamps[kb]))
      kt = k;
  const Isometry3d T_vehicle_target = base.T_vehicle_lidar * pair.T_base_target;
  auto residuals = [&](double offset) {
    return ref.residuals(sim_test::deskew(target.frames[kt], target.timestamps[kt] + offset,
                                          T_vehicle_target, d.trajectory, 1.5, 40.0),
                         0.3, 0.6);
  };
  const std::vector<double> good = residuals(pair.time_offset_s);
  INFO("median " << median(good) << " over " << good.size());
  CHECK(good.size() > 5000);
  CHECK(median(good) < 3.0 * 0.03);
  // Ignoring the clock offset puts the target ~0.5 m off along the travel direction.
  const std::vector<double> ignored = residuals(0.0);
  INFO("offset ignored: p90 " << quantile(ignored, 0.9) << " vs " << quantile(good, 0.9));
  CHECK(quantile(ignored, 0.9) > 2.0 * quantile(good, 0.9));
  // Without deskewing (one pose per frame) the points smear: larger residuals too.
  std::vector<Vec3d> rigid;
  const Isometry3d T0 =
      sim_test::sampled_pose(d.trajectory, target.timestamps[kt] + pair.time_offset_s) *
      T_vehicle_target;
  for (const auto& p : target.frames[kt].points)
    if (p.norm() > 1.5 && p.norm() < 40.0) rigid.push_back(T0 * p.cast<double>());
  const std::vector<double> smeared = ref.residuals(rigid, 0.3, 0.6);
  INFO("not deskewed: p90 " << quantile(smeared, 0.9));
  CHECK(quantile(smeared, 0.9) > 1.5 * quantile(good, 0.9));
}
