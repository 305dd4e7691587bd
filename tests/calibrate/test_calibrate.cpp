// ulc::calibrate_pair: TERRA then JEEP recover the 64-32 mounting with no guess, JEEP alone
// refines a disturbed guess, every refusal comes back as a status (never a crash), results are
// bit-identical for 1 and 2 threads, and the result-file entry carries what docs/design.md lists.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "calibrate_test_util.hpp"
#include "pipeline/calibrate.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/result_entry.hpp"
#include "ulc/io/result_file.hpp"

using namespace calibrate_test;
using ulc::CalibrateStatus;
using ulc::Stage;

namespace {

const ulc::sim::LidarRecording& base() {
  return drive_64_32().lidars[0];
}
const ulc::sim::LidarRecording& target() {
  return drive_64_32().lidars[1];
}
ulc::Isometry3d truth() {
  return drive_64_32().pairs[0].T_base_target;
}

}  // namespace

TEST_CASE("terra,jeep recovers the 64-32 mounting with no initial guess", "[calibrate]") {
  struct Call {
    std::string stage;
    double fraction;
  };
  std::vector<Call> calls;
  ulc::CalibrateOptions o;
  o.stages = {Stage::terra, Stage::jeep};  // six frames are too few for HOTS: see test_hots_stage
  o.time_offset_s = 0.0;  // the simulator's clocks are synchronised (else: test_vouch.cpp)
  o.progress = [&](const std::string& stage, double f) { calls.push_back({stage, f}); };
  const auto r = ulc::calibrate_pair(base().frames, base().timestamps, target().frames,
                                     target().timestamps, o);
  INFO(ulc::to_string(r.status) << ": " << r.reason);
  REQUIRE(r.success);
  CHECK(r.status == CalibrateStatus::ok);
  CHECK(r.reason.empty());
  const auto e = ulc::pose_error(truth(), r.T_base_target);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m");
  CHECK(ulc::is_calibration_success(e));

  // TERRA's rotation is a rotation initialisation; JEEP started from it (or from a later
  // hypothesis that won the snapshot's contest, pipeline/hypothesis_attempts.hpp: the frames are
  // taken together, so the free-space check judges them), with the ground vote's lever arm when
  // a confident vote backs that rotation (StartRotations::start), else from 0.
  REQUIRE(r.terra);
  REQUIRE(r.jeep);
  CHECK(r.terra->status == terra::SearchStatus::ok);
  CHECK(ulc::rotation_error_rad(truth().linear(), r.terra->rotation) < 10 * kDeg);
  REQUIRE(r.terra->hypothesis_used < r.terra->hypotheses.size());
  const ulc::Mat3d& start = r.terra->hypotheses[r.terra->hypothesis_used].rotation;
  CHECK(r.jeep->initial.linear() == start);
  const bool vote_backs =
      r.terra->motion && r.terra->motion->ok && r.terra->motion->method == "ground vote" &&
      ulc::rotation_error_rad(r.terra->motion->vote.rotation, start) <= 5.0 * kDeg;
  if (vote_backs) {
    CHECK(r.jeep->initial.translation() == r.terra->motion->vote.translation);
    // The vote's lever arm: on its 0.5 m grid, the height from the two ground planes.
    CHECK((r.jeep->initial.translation() - truth().translation()).norm() < 0.75);
  } else {
    CHECK(r.jeep->initial.translation() == ulc::Vec3d::Zero());
  }
  CHECK(r.jeep->status == jeep::JeepStatus::ok);
  CHECK(r.jeep->rounds >= 2);
  CHECK(r.jeep->frame_pairs == 5);
  CHECK(r.terra->stats.coarse.rotations > 0);
  CHECK(r.terra->stats.fine.rotations > 0);
  CHECK(r.terra->base_points == base().frames[0].size());
  CHECK(r.terra->target_points == target().frames[0].size());

  // Progress: terra's calls, then jeep's (each hypothesis's), each in [0, 1], nondecreasing,
  // ending at 1.
  const auto is_jeep = [](const std::string& stage) { return stage.rfind("jeep", 0) == 0; };
  REQUIRE(!calls.empty());
  CHECK(calls.front().stage == "terra");
  CHECK(is_jeep(calls.back().stage));
  CHECK(calls.back().fraction == 1.0);
  for (std::size_t k = 0; k < calls.size(); ++k) {
    CHECK(calls[k].fraction >= 0.0);
    CHECK(calls[k].fraction <= 1.0);
    if (k > 0 && calls[k].stage == calls[k - 1].stage)
      CHECK(calls[k].fraction >= calls[k - 1].fraction);
    if (k > 0 && calls[k].stage != calls[k - 1].stage) {
      CHECK(calls[k - 1].fraction == 1.0);  // a stage finishes before the next begins
      CHECK(is_jeep(calls[k].stage));
    }
  }
}

TEST_CASE("TERRA works on double clouds without point times, as on float ones",
          "[calibrate][types]") {
  ulc::CalibrateOptions o;
  o.stages = {Stage::terra};
  o.frame_index = 2;
  const auto a = as_vectors(base().frames);
  const auto b = as_vectors(target().frames);
  const auto r_double = ulc::calibrate_pair(a, base().timestamps, b, target().timestamps, o);
  const auto r_float = ulc::calibrate_pair(base().frames, base().timestamps, target().frames,
                                           target().timestamps, o);
  INFO(r_double.reason << " / " << r_float.reason);
  REQUIRE(r_double.success);
  REQUIRE(r_float.success);
  REQUIRE(r_double.terra);
  CHECK(r_double.terra->frame_index == 2);
  CHECK(r_double.terra->base_points == base().frames[2].size());
  CHECK(!r_double.jeep);
  for (const auto* r : {&r_double, &r_float}) {
    CHECK(r->T_base_target.translation() == ulc::Vec3d::Zero());
    CHECK(ulc::pose_error(truth(), r->T_base_target).rotation_deg < 10.0);
  }
  // Same points, other scalar: the descriptors may differ by rounding, the answer barely.
  CHECK(ulc::pose_error(r_float.T_base_target, r_double.T_base_target).rotation_deg < 1.0);
}

TEST_CASE("jeep alone refines a disturbed initial guess", "[calibrate]") {
  ulc::CalibrateOptions o;
  o.stages = {Stage::jeep};
  o.initial = disturbed(truth(), 17, 5.0 * kDeg, 2.0);  // the paper's disturbance
  o.time_offset_s = 0.0;                                // the simulator's clocks are synchronised
  // Base as float clouds, target as double clouds (both with point times, which deskewing
  // needs on a moving vehicle): mixed scalar types work together.
  const auto b = as_double_clouds(target().frames);
  const auto r = ulc::calibrate_pair(base().frames, base().timestamps, b, target().timestamps, o);
  INFO(ulc::to_string(r.status) << ": " << r.reason);
  REQUIRE(r.success);
  CHECK(!r.terra);
  REQUIRE(r.jeep);
  CHECK(same_bits(r.jeep->initial, *o.initial));
  const auto e = ulc::pose_error(truth(), r.T_base_target);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m");
  CHECK(ulc::is_calibration_success(e));
  CHECK(r.timing_s.terra == 0.0);
}

TEST_CASE("refusals come back as a status and a reason", "[calibrate][status]") {
  const auto& fa = base().frames;
  const auto& ta = base().timestamps;
  const auto& fb = target().frames;
  const auto& tb = target().timestamps;
  auto expect = [](const ulc::PairCalibration& r, CalibrateStatus status, const std::string& text) {
    INFO(ulc::to_string(r.status) << ": " << r.reason);
    CHECK(r.status == status);
    CHECK_FALSE(r.success);
    CHECK_THAT(r.reason, Catch::Contains(text));
  };

  ulc::CalibrateOptions o;
  o.stages = {Stage::jeep};
  expect(ulc::calibrate_pair(fa, ta, fb, tb, o), CalibrateStatus::initial_required,
         "initial extrinsic");
  o.initial = truth();
  o.initial->translation().x() = std::nan("");
  expect(ulc::calibrate_pair(fa, ta, fb, tb, o), CalibrateStatus::invalid_input, "not finite");

  o = {};
  o.stages = {Stage::jeep, Stage::terra};
  expect(ulc::calibrate_pair(fa, ta, fb, tb, o), CalibrateStatus::invalid_input, "order");
  o.stages = {};
  expect(ulc::calibrate_pair(fa, ta, fb, tb, o), CalibrateStatus::invalid_input, "no stage");

  o = {};
  o.stages = {Stage::terra, Stage::jeep};
  o.frame_index = fa.size();
  expect(ulc::calibrate_pair(fa, ta, fb, tb, o), CalibrateStatus::invalid_input, "past the end");
  o.frame_index = 0;
  const std::vector<double> short_times(ta.begin(), ta.end() - 1);
  expect(ulc::calibrate_pair(fa, short_times, fb, tb, o), CalibrateStatus::invalid_input,
         "counts differ");

  // TERRA on a target that only sees a wall 1.5 m away: nothing beyond d1, no overlap.
  std::vector<std::vector<Eigen::Vector3d>> near(1);
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j) near[0].emplace_back(1.5, 0.05 * i, 0.05 * j);
  o.stages = {Stage::terra, Stage::jeep};
  const auto terra_failed = ulc::calibrate_pair(fa, ta, near, std::vector<double>{ta[0]}, o);
  expect(terra_failed, CalibrateStatus::terra_failed, "TERRA: no_overlap");
  REQUIRE(terra_failed.terra);
  CHECK(terra_failed.terra->status == terra::SearchStatus::no_overlap);
  CHECK(!terra_failed.jeep);  // no stage runs after a failed one
  CHECK(same_bits(terra_failed.T_base_target, ulc::Isometry3d::Identity()));

  // JEEP that cannot settle in one round: the result keeps JEEP's input, and says why.
  o.stages = {Stage::jeep};
  o.initial = disturbed(truth(), 3, 2.0 * kDeg, 0.3);
  o.tuning.jeep.max_rounds = 1;
  o.tuning.jeep.frames = 2;
  const auto jeep_failed = ulc::calibrate_pair(fa, ta, fb, tb, o);
  expect(jeep_failed, CalibrateStatus::jeep_failed, "JEEP: not_converged");
  REQUIRE(jeep_failed.jeep);
  CHECK(jeep_failed.jeep->status == jeep::JeepStatus::not_converged);
  CHECK(jeep_failed.jeep->rounds == 1);
  CHECK(same_bits(jeep_failed.T_base_target, *o.initial));
}

TEST_CASE("calibrate_pair gives the same bits on 1 and 2 threads", "[calibrate][threads]") {
  ulc::CalibrateOptions o;
  o.stages = {Stage::terra, Stage::jeep};
  o.tuning.jeep.frames = 3;
  o.frame_index = 1;
  auto run = [&] {
    return ulc::calibrate_pair(base().frames, base().timestamps, target().frames,
                               target().timestamps, o);
  };
  tbb::task_arena one(1), two(2);
  const auto r1 = one.execute(run);
  const auto r2 = two.execute(run);
  INFO(r1.reason << " / " << r2.reason);
  CHECK(r1.status == r2.status);
  REQUIRE(r1.terra);
  REQUIRE(r2.terra);
  CHECK(std::memcmp(r1.terra->rotation.data(), r2.terra->rotation.data(), 9 * sizeof(double)) == 0);
  CHECK(r1.terra->stats.rotations() == r2.terra->stats.rotations());
  REQUIRE(r1.jeep);
  REQUIRE(r2.jeep);
  CHECK(r1.jeep->rounds == r2.jeep->rounds);
  CHECK(same_bits(r1.T_base_target, r2.T_base_target));
}

TEST_CASE("the result-file entry has the fields of docs/design.md", "[calibrate][result]") {
  ulc::CalibrateOptions o;
  o.stages = {Stage::terra};
  const auto c = ulc::calibrate_pair(base().frames, base().timestamps, target().frames,
                                     target().timestamps, o);
  REQUIRE(c.success);
  const ulc::io::PairResult r = ulc::io::to_pair_result(c, "lidar64", "lidar32");
  // Through the file format and back.
  const auto json = ulc::io::results_to_json({r});
  const auto back =
      ulc::io::results_from_json(ulc::io::parse_json(ulc::io::dump_json(json)), "<test>");
  REQUIRE(back.size() == 1);
  const auto& e = json.at("results")[0];
  for (const char* key :
       {"base", "target", "success", "status", "reason", "T_base_target", "translation_m",
        "rotation_quat_wxyz", "rpy_deg", "time_offset_s", "covariance_6x6", "stages", "timing_s"})
    CHECK(e.contains(key));
  CHECK(back[0].base == "lidar64");
  CHECK(back[0].target == "lidar32");
  CHECK(back[0].success);
  CHECK(back[0].status == "ok");
  CHECK(back[0].T_base_target.isApprox(c.T_base_target, 1e-15));
  CHECK(*back[0].time_offset_s == 0.0);  // no HOTS: clocks assumed synchronised
  CHECK(!back[0].covariance_6x6);
  for (const char* key : {"terra", "jeep", "odometry", "hots", "total"})
    CHECK(back[0].timing_s.at(key).is_number());
  CHECK(back[0].timing_s.at("terra").get<double>() == c.timing_s.terra);
  CHECK_FALSE(back[0].stages.contains("jeep"));  // only the stages that ran
  const auto& terra = back[0].stages.at("terra");
  CHECK(terra.at("status").get<std::string>() == "ok");
  CHECK(terra.at("mask_count").get<double>() == static_cast<double>(c.terra->mask_count));
  CHECK(terra.at("d1_used_m").get<double>() == c.terra->stats.d1_used);
  CHECK(terra.at("rotations_evaluated").get<double>() ==
        static_cast<double>(c.terra->stats.overlap.rotations + c.terra->stats.coarse.rotations +
                            c.terra->stats.fine.rotations));
  CHECK(terra.at("search_stages").at("coarse").at("rotations").get<double>() ==
        static_cast<double>(c.terra->stats.coarse.rotations));
  // The spellings agree with the matrix.
  const Eigen::Vector3d rpy = ulc::rpy_from_rotation(c.T_base_target.linear()) * (180.0 / M_PI);
  for (int k = 0; k < 3; ++k)
    CHECK(e.at("rpy_deg")[static_cast<std::size_t>(k)].get<double>() == Approx(rpy[k]));

  // A refusal still makes an entry: success false, a status word and a reason.
  o.stages = {Stage::jeep};
  const auto refused =
      ulc::io::to_pair_result(ulc::calibrate_pair(base().frames, base().timestamps, target().frames,
                                                  target().timestamps, o),
                              "lidar64", "lidar32");
  CHECK_FALSE(refused.success);
  CHECK(refused.status == "initial_required");
  CHECK_FALSE(refused.reason.empty());
  CHECK(refused.stages.empty());
}
