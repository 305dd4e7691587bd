// The window's tally of per-frame ground votes (pipeline/window_vote.hpp).
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <vector>

#include "../support/test_units.hpp"
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
