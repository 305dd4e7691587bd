// The free-space check (pipeline/free_space.hpp): in a closed street canyon the base's rays
// cross the whole inside, so the target's cloud placed at the truth contradicts nothing, while a
// target turned or shifted across the street puts its walls where the base saw through and sends
// its rays through the base's walls; the options are checked. In the pipeline: a parked rig's
// answer carries the verdict, a parked pitched VLP-16 whose JEEP accepted the scene's twin (seed
// 10) is refused by the base's rays, flicar-lift's Avia twin (seed 16) by the target's own, a
// refused twin is named as such rather than as a degenerate scene (64-tele seed 3), and a
// moving rig is not judged. A parked corner unit whose frame agrees with the base's off the
// ground below JEEP's own bound stands with the check behind it and is refused without it; such
// an answer needs the check and the two-way verdict to have judged it.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "calibrate_test_util.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/free_space.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/result_entry.hpp"

using namespace calibrate_test;
using ulc::Isometry3d;
using ulc::Vec3d;

namespace {

/// The six faces of a closed street canyon (x in [-20, 20] along it, y in [-5, 5], z in
/// [-2, 10]) on a 0.2 m grid: every ray of a LiDAR inside it comes back.
std::vector<Vec3d> canyon() {
  return box_faces(Vec3d(-20.0, -5.0, -2.0), Vec3d(20.0, 5.0, 10.0), 0.2);
}

/// The canyon as the target sees it from `T_base_target` (convex: every face in view).
std::vector<Vec3d> seen_from(const Isometry3d& T_base_target, const std::vector<Vec3d>& scene) {
  std::vector<Vec3d> out;
  for (const Vec3d& p : scene) out.push_back(T_base_target.inverse() * p);
  return out;
}

Isometry3d mount() {
  Isometry3d T = Isometry3d::Identity();
  T.linear() = ulc::so3_exp(Vec3d(0.1, -0.05, 0.4));
  T.translation() = Vec3d(1.2, 0.6, 0.3);
  return T;
}

ulc::PairCalibration calibrate_first_pair(const ulc::sim::Dataset& d) {
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  return ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, {});
}

}  // namespace

TEST_CASE("the free-space check: the truth contradicts nothing, a turned or shifted street does",
          "[calibrate][free_space]") {
  const std::vector<Vec3d> scene = canyon();
  const Isometry3d truth = mount();
  const std::vector<Vec3d> target = seen_from(truth, scene);
  const ulc::FreeSpaceOptions o;

  const ulc::FreeSpaceVerdict right = ulc::free_space_verdict(scene, target, truth, o);
  CHECK(right.judged > 1000);
  CHECK(right.contradicting == 0);
  CHECK(right.rays_judged > 1000);
  CHECK(right.rays_through == 0);

  // Turned about the vertical by 90 deg (the side walls across the street) and by 180 deg (the
  // street's twin, about the target rather than the street's centre), or shifted 2 m across
  // it: the target's walls stand where the base saw through.
  const auto turned = [&](double deg) {
    Isometry3d T = truth;
    T.linear() = ulc::so3_exp(Vec3d(0.0, 0.0, deg * kDeg)) * truth.linear();
    return T;
  };
  Isometry3d across = truth;
  across.translation() += Vec3d(0.0, 2.0, 0.0);
  for (const auto& [name, wrong] :
       {std::pair{"turned 90 deg", turned(90.0)}, std::pair{"turned 180 deg", turned(180.0)},
        std::pair{"2 m across", across}}) {
    const ulc::FreeSpaceVerdict v = ulc::free_space_verdict(scene, target, wrong, o);
    INFO(name << ": " << v.contradicting << " of " << v.judged << " points, " << v.rays_through
              << " of " << v.rays_judged << " rays");
    CHECK(v.judged > 1000);
    CHECK(v.share() > o.max_share);
    CHECK(v.rays_judged > 1000);
    CHECK(v.through_share() > o.max_through_share);
  }

  // Along the street only the end wall can tell: some contradiction, far less.
  Isometry3d along = truth;
  along.translation() += Vec3d(4.0, 0.0, 0.0);
  const ulc::FreeSpaceVerdict a = ulc::free_space_verdict(scene, target, along, o);
  CHECK(a.contradicting > 0);
  CHECK(a.share() < o.max_share);

  SECTION("a point that is not finite is skipped, in either cloud") {
    std::vector<Vec3d> base_nan = scene, target_nan = target;
    base_nan.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
    target_nan.emplace_back(0.0, std::numeric_limits<double>::infinity(), 0.0);
    const ulc::FreeSpaceVerdict n = ulc::free_space_verdict(base_nan, target_nan, truth, o);
    CHECK(n.contradicting == 0);
    CHECK(n.judged >= right.judged);
  }
  SECTION("a far point or a far answer is judged by nothing (its rays walk the base's cube only)") {
    std::vector<Vec3d> far_target = target;
    far_target.emplace_back(1e9, 0.0, 0.0);
    const ulc::FreeSpaceVerdict f = ulc::free_space_verdict(scene, far_target, truth, o);
    CHECK(f.judged == right.judged);
    CHECK(f.rays_through == 0);
    Isometry3d away = truth;
    away.translation() = Vec3d(1e7, 0.0, 0.0);
    const ulc::FreeSpaceVerdict a = ulc::free_space_verdict(scene, target, away, o);
    CHECK(a.judged == 0);
    CHECK(a.rays_judged == 0);
  }
}

TEST_CASE("the free-space options are checked before any allocation", "[calibrate][free_space]") {
  ulc::FreeSpaceOptions o;
  CHECK(ulc::free_space_problem(o).empty());
  o.voxel = 0.0;
  CHECK_FALSE(ulc::free_space_problem(o).empty());
  o = {};
  o.range = 1e9;
  CHECK_FALSE(ulc::free_space_problem(o).empty());
  o = {};
  o.stride = 0;
  CHECK_FALSE(ulc::free_space_problem(o).empty());
  o = {};
  o.min_off_ground_overlap = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(ulc::free_space_problem(o).empty());
  o.min_off_ground_overlap = -0.1;
  CHECK_FALSE(ulc::free_space_problem(o).empty());

  const ulc::sim::Dataset d = parked_snapshot("64-32", 1);
  ulc::CalibrateOptions c;
  c.tuning.free_space.voxel = std::numeric_limits<double>::quiet_NaN();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  const ulc::PairCalibration r =
      ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, c);
  CHECK(r.status == ulc::CalibrateStatus::invalid_input);
  CHECK(r.reason.find("free space") != std::string::npos);
}

TEST_CASE("a parked rig's answer is judged by the free space the base saw",
          "[calibrate][free_space]") {
  SECTION("64-32: right, and the verdict is in the result") {
    const ulc::sim::Dataset d = parked_snapshot("64-32", 1);
    const ulc::PairCalibration r = calibrate_first_pair(d);
    REQUIRE(r.success);
    CHECK(ulc::is_calibration_success(ulc::pose_error(d.pairs[0].T_base_target, r.T_base_target)));
    REQUIRE(r.jeep);
    REQUIRE(r.jeep->free_space);
    CHECK(r.jeep->free_space->judged >= ulc::FreeSpaceOptions{}.min_points);
    CHECK(r.jeep->free_space->share() < 0.05);
    CHECK(r.jeep->free_space->through_share() < ulc::FreeSpaceOptions{}.max_through_share);
    const auto j = ulc::io::jeep_to_json(*r.jeep);
    CHECK(j.at("free_space").at("judged").get<std::size_t>() == r.jeep->free_space->judged);
    CHECK(j.at("free_space").at("rays_through").get<std::size_t>() ==
          r.jeep->free_space->rays_through);
  }
  SECTION("pitched-90 seed 10: the twin JEEP accepts is refused") {
    const ulc::sim::Dataset d = parked_snapshot("pitched-90", 10);
    const ulc::PairCalibration r = calibrate_first_pair(d);
    const auto e = ulc::pose_error(d.pairs[0].T_base_target, r.T_base_target);
    INFO(ulc::to_string(r.status) << ": " << r.reason << " (" << e.rotation_deg << " deg)");
    CHECK_FALSE((r.success && !ulc::is_calibration_success(e)));
    CHECK(r.status == ulc::CalibrateStatus::jeep_failed);
    CHECK(r.reason.find("empty space") != std::string::npos);
    REQUIRE(r.jeep);
    REQUIRE(r.jeep->free_space);
    CHECK(r.jeep->free_space->share() > ulc::FreeSpaceOptions{}.max_share);
  }
  SECTION("flicar-lift seed 16: the Avia's twin sends its rays through the base's walls") {
    const ulc::sim::Dataset d = parked_snapshot("flicar-lift", 16);
    const auto* truth = pair_with_target(d, "avia");
    REQUIRE(truth);
    const auto& a = *d.find(truth->base);
    const auto& b = *d.find(truth->target);
    const ulc::PairCalibration r =
        ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, {});
    const auto e = ulc::pose_error(truth->T_base_target, r.T_base_target);
    INFO(ulc::to_string(r.status) << ": " << r.reason << " (" << e.rotation_deg << " deg)");
    CHECK_FALSE((r.success && !ulc::is_calibration_success(e)));
    REQUIRE(r.jeep);
    REQUIRE(r.jeep->free_space);
    const ulc::FreeSpaceVerdict& v = *r.jeep->free_space;
    CHECK(v.through_share() > ulc::FreeSpaceOptions{}.max_through_share);
    CHECK(r.reason.find("through surfaces the base saw") != std::string::npos);
    // At the truth its rays meet only what the Avia itself saw.
    const ulc::FreeSpaceVerdict at_truth = ulc::free_space_verdict(
        a.frames[0], b.frames[0], truth->T_base_target, ulc::FreeSpaceOptions{});
    CHECK(at_truth.rays_judged >= ulc::FreeSpaceOptions{}.min_points);
    CHECK(at_truth.through_share() < 0.05);
  }
  SECTION("64-tele seed 3: the Tele's twin is named a look-alike, not a degenerate scene") {
    // JEEP accepts the street's forward/backward twin (179 deg off); its narrow single frame
    // leaves a direction of that registration free, but the refusal is the check's.
    const ulc::sim::Dataset d = parked_snapshot("64-tele", 3);
    REQUIRE(d.pairs.size() == 1);
    const ulc::PairCalibration r = calibrate_first_pair(d);
    const auto e = ulc::pose_error(d.pairs[0].T_base_target, r.T_base_target);
    INFO(ulc::to_string(r.status) << ": " << r.reason << " (" << e.rotation_deg << " deg)");
    CHECK_FALSE((r.success && !ulc::is_calibration_success(e)));
    CHECK(r.status == ulc::CalibrateStatus::jeep_failed);
    CHECK(r.reason.find("a look-alike of the scene") != std::string::npos);
    CHECK(r.observability_problem.empty());
    CHECK(r.unobservable.empty());
    REQUIRE(r.jeep);
    CHECK_FALSE(r.jeep->observability);
  }
  SECTION("a moving rig is not judged by it") {
    const ulc::sim::Dataset& d = drive_64_32_hots();
    ulc::CalibrateOptions o;
    o.stages = {ulc::Stage::terra, ulc::Stage::jeep};
    const auto& a = d.lidars[0];
    const auto& b = d.lidars[1];
    const ulc::PairCalibration r =
        ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
    REQUIRE(r.jeep);
    CHECK_FALSE(r.jeep->free_space);
  }
}

TEST_CASE("a parked corner unit stands at a lower off-ground overlap with the check behind it",
          "[calibrate][free_space]") {
  // ring-5x16 seed 1's rear-right VLP-16, 2.7 m from the base: at the truth its single frame
  // agrees with the base's off the ground below JEEP's own 0.25
  // (docs/experiments/snapshot_acceptance.md).
  const ulc::sim::Dataset d = parked_snapshot("ring-5x16", 1);
  const auto* truth = pair_with_target(d, "rear_right");
  REQUIRE(truth);
  const auto& a = *d.find(truth->base);
  const auto& b = *d.find(truth->target);
  const double jeep_bound = jeep::AcceptanceOptions{}.min_off_ground_overlap;

  const ulc::PairCalibration r =
      ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, {});
  const auto e = ulc::pose_error(truth->T_base_target, r.T_base_target);
  INFO(ulc::to_string(r.status) << ": " << r.reason << " (" << e.rotation_deg << " deg, "
                                << e.translation_m << " m)");
  REQUIRE(r.success);
  CHECK(ulc::is_calibration_success(e));
  REQUIRE(r.jeep);
  CHECK(r.jeep->off_ground_overlap < jeep_bound);
  CHECK(r.jeep->off_ground_overlap >= ulc::FreeSpaceOptions{}.min_off_ground_overlap);
  REQUIRE(r.jeep->free_space);
  CHECK(r.jeep->free_space->judged >= ulc::FreeSpaceOptions{}.min_points);
  CHECK(r.jeep->free_space->rays_judged >= ulc::FreeSpaceOptions{}.min_points);

  // Without the check, JEEP's own rule judges the snapshot and refuses it.
  ulc::CalibrateOptions unchecked;
  unchecked.tuning.free_space.enabled = false;
  const ulc::PairCalibration plain =
      ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, unchecked);
  INFO("without the check: " << ulc::to_string(plain.status) << ": " << plain.reason);
  CHECK_FALSE(plain.success);
}

TEST_CASE("an answer below JEEP's off-ground bound stands only when both checks judged it",
          "[calibrate][free_space]") {
  const ulc::FreeSpaceOptions o;
  ulc::FreeSpaceVerdict judged;
  judged.judged = judged.rays_judged = o.min_points;
  CHECK(ulc::unvouched_overlap_refusal(0.30, 0.25, std::nullopt, false, o).empty());
  CHECK(ulc::unvouched_overlap_refusal(0.20, 0.25, judged, true, o).empty());
  const std::string moved = ulc::unvouched_overlap_refusal(0.20, 0.25, std::nullopt, true, o);
  CHECK(moved.find("0.20, below 0.25") != std::string::npos);
  CHECK(moved.find("could not run") != std::string::npos);
  ulc::FreeSpaceVerdict few_rays = judged;
  few_rays.rays_judged = o.min_points - 1;
  CHECK(ulc::unvouched_overlap_refusal(0.20, 0.25, few_rays, true, o).find("too few") !=
        std::string::npos);
  ulc::FreeSpaceVerdict few_points = judged;
  few_points.judged = o.min_points - 1;
  CHECK_FALSE(ulc::unvouched_overlap_refusal(0.20, 0.25, few_points, true, o).empty());
  CHECK(ulc::unvouched_overlap_refusal(0.20, 0.25, judged, false, o).find("backward") !=
        std::string::npos);
}
