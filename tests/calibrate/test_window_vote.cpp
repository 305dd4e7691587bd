// The window's tally of per-frame ground votes (pipeline/window_vote.hpp).
#include <tbb/task_arena.h>
#include <Eigen/Geometry>

#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "../support/test_units.hpp"
#include "../terra/terra_test_util.hpp"
#include "pipeline/window_vote.hpp"

namespace {

using ulc_test::kDeg;

terra::GroundVoteResult vote_about_z(double yaw_deg, bool ok, double score) {
  terra::GroundVoteResult v;
  v.ok = ok;
  v.score = score;
  v.rotation = Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  if (!ok) v.reason = "not sure at " + std::to_string(int(yaw_deg));
  return v;
}

}  // namespace

TEST_CASE("the frames voted are spread over the window", "[calibrate][window_vote]") {
  using V = std::vector<std::size_t>;
  CHECK(ulc::vote_frame_indices(20, 3, 19) == V{0, 9, 19});
  CHECK(ulc::vote_frame_indices(21, 3, 20) == V{0, 10, 20});
  CHECK(ulc::vote_frame_indices(20, 2, 19) == V{0, 19});
  CHECK(ulc::vote_frame_indices(2, 3, 1) == V{0, 1});  // never more frames than the window has
  CHECK(ulc::vote_frame_indices(20, 1, 19) == V{19});  // one: the anchor frame
  CHECK(ulc::vote_frame_indices(20, 1, 0) == V{0});
  CHECK(ulc::vote_frame_indices(1, 3, 0) == V{0});
  CHECK(ulc::vote_frame_indices(0, 3, 0).empty());
}

TEST_CASE("the window answers with the rotation most confident frames back",
          "[calibrate][window_vote]") {
  SECTION("two of three agree within 5 deg: their answer, the higher-scoring one reported") {
    const auto t = ulc::tally_votes({vote_about_z(170.0, true, 0.3), vote_about_z(2.0, true, 0.2),
                                     vote_about_z(4.0, true, 0.25)},
                                    5.0, 20.0);
    CHECK(t.ok);
    CHECK(t.chosen == 2);
    CHECK(t.confident == 3);
    CHECK(t.agreeing == 2);
  }
  SECTION("one confident frame, the others unsure: its answer") {
    const auto t = ulc::tally_votes({vote_about_z(90.0, false, 0.5), vote_about_z(3.0, true, 0.2),
                                     vote_about_z(180.0, false, 0.1)},
                                    5.0, 20.0);
    CHECK(t.ok);
    CHECK(t.chosen == 1);
    CHECK(t.confident == 1);
    CHECK(t.agreeing == 1);
  }
  SECTION("two frames sure of rotations 175 deg apart: no answer, and why") {
    const auto t = ulc::tally_votes({vote_about_z(0.0, true, 0.4), vote_about_z(175.0, true, 0.2),
                                     vote_about_z(60.0, false, 0.6)},
                                    5.0, 20.0);
    CHECK_FALSE(t.ok);
    CHECK(t.chosen == 0);  // the higher-scoring of the two is reported
    CHECK(t.confident == 2);
    CHECK(t.agreeing == 1);
    CHECK(t.reason.find("175 deg apart") != std::string::npos);
  }
  SECTION("two frames sure of rotations 8 deg apart: one answer, the higher-scoring") {
    const auto t = ulc::tally_votes({vote_about_z(0.0, true, 0.2), vote_about_z(8.0, true, 0.3),
                                     vote_about_z(120.0, false, 0.6)},
                                    5.0, 20.0);
    CHECK(t.ok);
    CHECK(t.chosen == 1);
    CHECK(t.confident == 2);
    CHECK(t.agreeing == 1);
  }
  SECTION("two frames sure of rotations 25 deg apart: no answer") {
    const auto t =
        ulc::tally_votes({vote_about_z(0.0, true, 0.2), vote_about_z(25.0, true, 0.3)}, 5.0, 20.0);
    CHECK_FALSE(t.ok);
    CHECK(t.reason.find("25 deg apart") != std::string::npos);
  }
  SECTION("no confident frame: the highest-scoring vote reported with its reason") {
    const auto t = ulc::tally_votes({vote_about_z(10.0, false, 0.1), vote_about_z(20.0, false, 0.3),
                                     vote_about_z(30.0, false, 0.2)},
                                    5.0, 20.0);
    CHECK_FALSE(t.ok);
    CHECK(t.chosen == 1);
    CHECK(t.confident == 0);
    CHECK(t.reason == "not sure at 20");
  }
  SECTION("no vote at all") {
    const auto t = ulc::tally_votes({}, 5.0, 20.0);
    CHECK_FALSE(t.ok);
    CHECK_FALSE(t.reason.empty());
  }
}

namespace {

/// Three views of one narrow LiDAR mount (R, t) over the test street's base scan, each made
/// ready to vote with the base scan's free space, and their own votes.
struct Views {
  std::vector<terra::GroundVoteInput> inputs;
  std::vector<terra::GroundVoteResult> votes;
};

Views three_views(const ulc::Mat3d& R, const ulc::Vec3d& t, const std::vector<double>& looks_deg) {
  const auto base = terra_test::scan(ulc::Mat3d::Identity(), ulc::Vec3d::Zero(), 64, 1024);
  Views v;
  for (const double look : looks_deg) {
    const ulc::Vec3d axis(std::cos(look * kDeg), std::sin(look * kDeg), -0.05);
    v.inputs.push_back(terra::prepare_ground_vote(base, terra_test::narrow_scan(R, t, axis, 10.0)));
    v.votes.push_back(terra::ground_vote(v.inputs.back()));
    terra::add_free_space(v.inputs.back(), base, {});
  }
  return v;
}

}  // namespace

TEST_CASE("the pooled vote scores every frame's peaks on every frame", "[calibrate][window_vote]") {
  const ulc::Mat3d R = ulc::rotation_from_rpy(0.3, -0.2, 2.4);
  const ulc::Vec3d t(1.3, -0.4, 0.2);
  // The mount's view swept 0, 10 and 20 deg to the left along the street, as a turn sweeps
  // it: the last frame alone is unsure (its best rotation 90 deg off), the pool is not.
  const Views v = three_views(R, t, {0.0, 10.0, 20.0});
  CHECK_FALSE(v.votes[2].ok);
  const ulc::PooledVote pooled = ulc::pool_votes(v.inputs, v.votes, {});
  INFO(pooled.vote.reason << ", score " << pooled.vote.score << ", margin " << pooled.vote.margin);
  REQUIRE(pooled.vote.ok);
  CHECK(ulc::rotation_error_rad(R, pooled.vote.rotation) / kDeg < 3.0);
  // Its score is the mean share of its pose over the frames; the frames' own votes agree.
  double mean = 0.0;
  for (const terra::GroundVoteInput& in : v.inputs)
    mean += terra::pose_share(in, {pooled.vote.rotation, pooled.vote.translation}, {}) / 3.0;
  CHECK(pooled.vote.score == Approx(mean));
  // The same bits on 1 and 2 threads.
  auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    return arena.execute([&] { return ulc::pool_votes(v.inputs, v.votes, {}); });
  };
  const ulc::PooledVote one = run(1), two = run(2);
  CHECK(one.vote.rotation == two.vote.rotation);
  CHECK(one.vote.score == two.vote.score);
  CHECK(one.vote.margin == two.vote.margin);
  CHECK(one.source == two.source);
}

TEST_CASE("the pooled vote is silent when no frame could vote", "[calibrate][window_vote]") {
  const std::vector<ulc::Vec3d> empty;
  const auto base = terra_test::scan(ulc::Mat3d::Identity(), ulc::Vec3d::Zero(), 32, 720);
  const std::vector<terra::GroundVoteInput> inputs = {terra::prepare_ground_vote(base, empty),
                                                      terra::prepare_ground_vote(empty, base)};
  const std::vector<terra::GroundVoteResult> votes = {terra::ground_vote(inputs[0]),
                                                      terra::ground_vote(inputs[1])};
  const ulc::PooledVote pooled = ulc::pool_votes(inputs, votes, {});
  CHECK_FALSE(pooled.vote.ok);
  CHECK(pooled.vote.reason == votes[0].reason);
  CHECK_FALSE(ulc::pool_votes({}, {}, {}).vote.ok);
}

TEST_CASE("the window's answer: the tally's when sure, the pool's when not, none when they differ",
          "[calibrate][window_vote]") {
  const std::vector<terra::GroundVoteResult> sure = {vote_about_z(2.0, true, 0.3),
                                                     vote_about_z(4.0, true, 0.2)};
  const std::vector<terra::GroundVoteResult> unsure = {vote_about_z(90.0, false, 0.3),
                                                       vote_about_z(170.0, false, 0.2)};
  auto pool = [](double yaw_deg, bool ok, std::size_t source) {
    return ulc::PooledVote{vote_about_z(yaw_deg, ok, 0.25), source};
  };
  // The sure tally's answer, when the pool is unsure or sure of a rotation within 20 deg of it.
  auto check_tally_answer = [&](const ulc::PooledVote& pooled) {
    const auto t = ulc::tally_votes(sure, 5.0, 20.0);
    const auto a = ulc::window_answer(sure, t, pooled, 20.0);
    CHECK(a.tally.ok);
    CHECK_FALSE(a.pooled);
    CHECK(a.vote.rotation == sure[t.chosen].rotation);
  };
  // The pool's answer, sure or not as the pool is, and its frame.
  auto check_pool_answer = [&](const std::vector<terra::GroundVoteResult>& votes,
                               const ulc::PooledVote& pooled) {
    const auto a = ulc::window_answer(votes, ulc::tally_votes(votes, 5.0, 20.0), pooled, 20.0);
    CHECK(a.tally.ok == pooled.vote.ok);
    CHECK(a.pooled);
    CHECK(a.tally.chosen == pooled.source);
    CHECK(ulc::rotation_error_rad(a.vote.rotation, pooled.vote.rotation) < 1e-12);
    return a;
  };
  SECTION("the tally sure, the pool not but near it: the tally's answer") {
    check_tally_answer(pool(15.0, false, 1));
  }
  SECTION("the tally sure, the pool unsure of a rotation 173 deg off: unsure, the pool's guess") {
    const auto a = check_pool_answer(sure, pool(175.0, false, 1));
    CHECK_THAT(a.tally.reason, Catch::Contains("173 deg from their tally's: not sure at 175"));
  }
  SECTION("the tally unsure, the pool sure: the pool's answer and frame") {
    check_pool_answer(unsure, pool(3.0, true, 1));
  }
  SECTION("both sure, 173 deg apart: no answer, and why") {
    const auto t = ulc::tally_votes(sure, 5.0, 20.0);
    const auto a = ulc::window_answer(sure, t, pool(175.0, true, 0), 20.0);
    CHECK_FALSE(a.tally.ok);
    CHECK_THAT(a.tally.reason, Catch::Contains("173 deg apart"));
  }
  SECTION("both sure, 10 deg apart: the tally's answer") {
    check_tally_answer(pool(12.0, true, 0));
  }
  SECTION("neither sure: none, the pool's vote and reason reported") {
    CHECK(check_pool_answer(unsure, pool(60.0, false, 0)).tally.reason == "not sure at 60");
  }
}
