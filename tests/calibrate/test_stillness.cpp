// The stillness check (pipeline/stillness.hpp): frames of a closed room taken from one spot are
// still, from a spot that moves 10 cm per frame they are not (and the move is measured); a
// corridor cannot show a move along it, so its frames are not judged still either way. In the
// pipeline: a parked rig recorded for seconds is calibrated as a snapshot (HOTS skipped, the
// result says why) without a known clock offset, and a moving drive is judged moving.
#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "calibrate_test_util.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/parked_stack.hpp"
#include "pipeline/stillness.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/result_entry.hpp"

using namespace calibrate_test;
using ulc::Isometry3d;
using ulc::Vec3d;

namespace {

using Frame = std::vector<Vec3d>;

/// A closed room with a pillar in it, every face in view from inside.
std::vector<Vec3d> room() {
  std::vector<Vec3d> scene = box_faces(Vec3d(-20, -6, -2), Vec3d(20, 6, 8), 0.2);
  const std::vector<Vec3d> pillar = box_faces(Vec3d(4, 2, -2), Vec3d(5, 3, 8), 0.1, {0, 1});
  scene.insert(scene.end(), pillar.begin(), pillar.end());
  return scene;
}

/// A corridor along x: two walls and the floor, no ends within reach.
std::vector<Vec3d> corridor() {
  return box_faces(Vec3d(-150, -3, -2), Vec3d(150, 3, 6), 0.25, {1, 2});
}

/// The scene as a LiDAR at `pose` (T_world_lidar) sees it, within `range` metres.
Frame frame_from(const Isometry3d& pose, const std::vector<Vec3d>& scene, double range = 60.0) {
  Frame out;
  const Isometry3d inv = pose.inverse();
  for (const Vec3d& p : scene) {
    const Vec3d q = inv * p;
    if (q.norm() <= range) out.push_back(q);
  }
  return out;
}

/// Ten frames 0.1 s apart from poses moving `step` metres along x per frame.
struct Recording {
  std::vector<Frame> frames;
  std::vector<double> times;
};

Recording record(const std::vector<Vec3d>& scene, double step) {
  Recording r;
  for (int k = 0; k < 10; ++k) {
    Isometry3d pose = Isometry3d::Identity();
    pose.translation() = Vec3d(step * k, 0.0, 0.0);
    r.frames.push_back(frame_from(pose, scene));
    r.times.push_back(100.0 + 0.1 * k);
  }
  return r;
}

/// A seeded 64-32 rig parked 3 s into its route, recorded for `seconds`, decimated 4x.
ulc::sim::Dataset parked_64_32(double seconds) {
  ulc::sim::SimulationOptions o;
  o.seconds = seconds;
  o.seed = 2;
  o.decimation = 4;
  o.static_at_s = 3.0;
  return ulc::sim::simulate(*ulc::sim::scenario("64-32"), o).dataset;
}

}  // namespace

TEST_CASE("the stillness check compares frames spread over the recording, the last among them",
          "[calibrate][stillness]") {
  using ulc::stillness_detail::compared_frames;
  CHECK(compared_frames(10, 8) == std::vector<std::size_t>{1, 2, 3, 4, 5, 6, 7, 9});
  CHECK(compared_frames(101, 4) == std::vector<std::size_t>{25, 50, 75, 100});
  CHECK(compared_frames(3, 8) == std::vector<std::size_t>{1, 2});
  CHECK(compared_frames(1, 8).empty());
  CHECK(compared_frames(10, 0).empty());
}

TEST_CASE("frames of a room from one spot are still; from a moving spot they are not",
          "[calibrate][stillness]") {
  const std::vector<Vec3d> scene = room();
  const ulc::StillnessOptions o;

  const Recording parked = record(scene, 0.0);
  const ulc::StillnessReport still = ulc::judge_stillness(parked.frames, parked.times, o);
  INFO(still.reason);
  CHECK(still.still);
  CHECK(still.decided);
  CHECK(still.frames_compared == 8);
  CHECK(still.span_s == Approx(0.9));
  CHECK(still.max_travel_m < 0.005);
  CHECK(still.min_condition >= o.min_condition);
  CHECK_THAT(still.reason, Catch::StartsWith("the rig stood still"));

  const Recording moving = record(scene, 0.1);
  const ulc::StillnessReport moved = ulc::judge_stillness(moving.frames, moving.times, o);
  INFO(moved.reason);
  CHECK_FALSE(moved.still);
  CHECK(moved.decided);
  CHECK(moved.frames_compared == 1);  // the first frame away from the first ends the check
  CHECK(moved.max_travel_m == Approx(0.1).margin(0.01));
  CHECK_THAT(moved.reason, Catch::StartsWith("the rig moved: base frame 1, 0.1 s after"));
}

TEST_CASE("a corridor cannot show a move along it: its frames are never judged still",
          "[calibrate][stillness]") {
  const std::vector<Vec3d> scene = corridor();
  for (const double step : {0.0, 0.3}) {
    const Recording r = record(scene, step);
    const ulc::StillnessReport report = ulc::judge_stillness(r.frames, r.times, {});
    INFO("step " << step << ": " << report.reason);
    CHECK_FALSE(report.still);
    CHECK_FALSE(report.decided);
    CHECK(report.min_condition < ulc::StillnessOptions{}.min_condition);
    CHECK_THAT(report.reason, Catch::StartsWith("not judged still"));
  }
}

TEST_CASE("a parked rig's stack holds its first frames' finite points, on the base's first time",
          "[calibrate][stillness]") {
  Recording a = record(room(), 0.0);
  const Recording b = record(corridor(), 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  a.frames[1].push_back(Vec3d(nan, 0.0, 1.0));
  const ulc::ParkedStack<std::vector<Frame>, std::vector<Frame>> s =
      ulc::parked_stack(a.frames, a.times, b.frames, ulc::ParkedStackOptions{3}, 0.4);
  CHECK(s.frames_a == 3);
  CHECK(s.frames_b == 3);
  REQUIRE(s.a.size() == 1);
  REQUIRE(s.b.size() == 1);
  CHECK(s.a[0].size() == 3 * a.frames[0].size());  // the NaN point left out
  CHECK(s.b[0].size() == 3 * b.frames[0].size());
  CHECK_FALSE(s.a[0].has_times());  // a standing rig's sweep has nothing to undo
  CHECK(s.a[0].points[a.frames[0].size()] == a.frames[1][0]);
  CHECK(s.times_a == std::vector<double>{100.0});
  CHECK(s.times_b == s.times_a);
  // Frames of one spot repeat each other's cells: every cell seen by all three.
  CHECK(s.views_a == Approx(3.0));
  CHECK(s.views_b == Approx(3.0));
  CHECK(s.covariance_scale() == Approx(3.0));

  const auto all = ulc::parked_stack(a.frames, a.times, b.frames, ulc::ParkedStackOptions{50}, 0.4);
  CHECK(all.frames_a == a.frames.size());  // no more than the recording has

  const auto none = ulc::parked_stack(a.frames, a.times, b.frames, ulc::ParkedStackOptions{0}, 0.4);
  CHECK(none.frames_a == 1);  // 0 frames asked: the first frame alone, never an empty stack
  REQUIRE(none.a.size() == 1);
  CHECK(none.a[0].size() == a.frames[0].size());
  CHECK(none.covariance_scale() == Approx(1.0));
}

TEST_CASE("frames that fill new cells are each cell's only view", "[calibrate][stillness]") {
  const std::vector<Frame> rosette{
      {Vec3d(0, 0, 0), Vec3d(0.1, 0, 0)}, {Vec3d(5, 0, 0)}, {Vec3d(10, 0, 0), Vec3d(0.2, 0, 0)}};
  CHECK(ulc::views_per_cell(rosette, 3, 0.4) == Approx(4.0 / 3.0));  // 4 views of 3 cells
  CHECK(ulc::views_per_cell(rosette, 2, 0.4) == Approx(1.0));
  CHECK(ulc::views_per_cell(rosette, 3, 0.0) == 0.0);  // no cells: the scale stays 1
}

TEST_CASE("a parked rig recorded for seconds is calibrated without a clock offset, HOTS skipped",
          "[calibrate][stillness]") {
  const ulc::sim::Dataset d = parked_64_32(2.0);
  const auto& a = d.lidars.at(0);
  const auto& b = d.lidars.at(1);
  REQUIRE(a.frames.size() >= ulc::StageTuning{}.hots_min_frames);
  const ulc::PairCalibration r =
      ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, {});
  INFO(ulc::to_string(r.status) << ": " << r.reason);
  REQUIRE(r.success);
  const auto e = ulc::pose_error(d.pairs.at(0).T_base_target, r.T_base_target);
  INFO(e.rotation_deg << " deg, " << e.translation_m << " m");
  CHECK(ulc::is_calibration_success(e));
  REQUIRE(r.hots);
  CHECK(r.hots->run == ulc::HotsRun::skipped);
  REQUIRE(r.hots->stillness);
  CHECK(r.hots->stillness->still);
  CHECK_THAT(r.hots->reason, Catch::StartsWith("the rig stood still") &&
                                 Catch::Contains("HOTS needs a moving rig"));
  REQUIRE(r.jeep);
  CHECK(r.jeep->free_space);  // judged as a snapshot is
  CHECK(r.jeep->frame_pairs == 1);
  CHECK(r.jeep->stacked_frames_base == ulc::ParkedStackOptions{}.frames);
  CHECK(r.jeep->stacked_frames_target == ulc::ParkedStackOptions{}.frames);
  REQUIRE(r.clock);
  CHECK(r.clock->verdict == "parked");
  CHECK_THAT(r.clock->note, Catch::Contains("need not be: the rig stood still"));
  const ulc::io::PairResult j = ulc::io::to_pair_result(r, "lidar64", "lidar32");
  CHECK(j.stages.at("hots").at("stillness").at("still").get<bool>());
  CHECK(j.stages.at("hots").at("status").get<std::string>() == "skipped");
  CHECK(j.stages.at("jeep").at("stacked_frames_base").get<std::size_t>() ==
        r.jeep->stacked_frames_base);

  SECTION("a refusal on the base's odometry is not run again on the joint one: none ran") {
    ulc::CalibrateOptions o;
    o.tuning.odometry_choice.min_duration_s = 1.0;  // the automatic choice takes the base's
    o.tuning.vouch.success_translation_m = 1e-6;    // any two-way gap refuses the answer
    std::atomic<int> jeep_runs{0};
    o.progress = [&](const std::string& stage, double fraction) {
      if (stage == "jeep" && fraction == 0.0) ++jeep_runs;
    };
    const ulc::PairCalibration u =
        ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
    INFO(ulc::to_string(u.status) << ": " << u.reason);
    CHECK(u.status == ulc::CalibrateStatus::uncertain);
    CHECK(jeep_runs == 1);
  }

  SECTION("HOTS alone on it fails and says why") {
    ulc::CalibrateOptions o;
    o.stages = {ulc::Stage::hots};
    o.initial = d.pairs.at(0).T_base_target;
    const ulc::PairCalibration h =
        ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
    CHECK(h.status == ulc::CalibrateStatus::hots_failed);
    CHECK_THAT(h.reason, Catch::Contains("the rig stood still"));
  }
}
