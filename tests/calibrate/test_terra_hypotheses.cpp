// TERRA's hypotheses (pipeline/terra_hypotheses.hpp): the search's optima, best first,
// one per basin, and the first always the search's own answer.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>

#include "../support/test_units.hpp"
#include "pipeline/terra_hypotheses.hpp"
#include "pipeline/terra_stage.hpp"

namespace {

using ulc_test::kDeg;

ulc::Mat3d yaw(double deg) {
  return Eigen::AngleAxisd(deg * kDeg, ulc::Vec3d::UnitZ()).toRotationMatrix();
}

terra::RotationCandidate candidate(double yaw_deg, double distance) {
  terra::RotationCandidate c;
  c.rotation = yaw(yaw_deg);
  c.distance = distance;
  c.mask_count = 100;
  return c;
}

/// A successful search whose refined optima are `refined` (in seed order).
terra::SearchResult search_with(std::vector<terra::RotationCandidate> refined) {
  terra::SearchResult s;
  s.status = terra::SearchStatus::ok;
  s.refined = std::move(refined);
  std::size_t best = 0;
  for (std::size_t k = 1; k < s.refined.size(); ++k)
    if (s.refined[k].distance < s.refined[best].distance) best = k;
  s.rotation = s.refined[best].rotation;
  s.distance = s.refined[best].distance;
  return s;
}

std::vector<double> yaws_of(const std::vector<terra::RotationCandidate>& h) {
  std::vector<double> out;
  for (const auto& c : h) out.push_back(std::atan2(c.rotation(1, 0), c.rotation(0, 0)) / kDeg);
  return out;
}

}  // namespace

TEST_CASE("TERRA's hypotheses are its optima, best first, one per basin",
          "[calibrate][terra_hypotheses]") {
  // Seed order differs from distance order; 2 and 8 deg are one basin (10 deg apart at most),
  // 166 deg is the street's twin.
  const terra::SearchResult s =
      search_with({candidate(166.0, 0.004), candidate(8.0, 0.003), candidate(2.0, 0.005),
                   candidate(-60.0, 0.006), candidate(100.0, 0.006)});
  const auto h = ulc::terra_hypotheses(s, 10, 10.0 * kDeg);
  const std::vector<double> yaws = yaws_of(h);
  REQUIRE(yaws.size() == 4);
  CHECK(yaws[0] == Approx(8.0));  // the search's answer
  CHECK(h[0].rotation.isApprox(s.rotation));
  CHECK(yaws[1] == Approx(166.0));
  CHECK(yaws[2] == Approx(-60.0));  // equal distances: seed order
  CHECK(yaws[3] == Approx(100.0));
  for (std::size_t k = 1; k < h.size(); ++k) CHECK(h[k - 1].distance <= h[k].distance);

  // At most max_count; a smaller separation keeps the 2-deg optimum as its own hypothesis.
  CHECK(ulc::terra_hypotheses(s, 2, 10.0 * kDeg).size() == 2);
  const auto fine = yaws_of(ulc::terra_hypotheses(s, 10, 5.0 * kDeg));
  REQUIRE(fine.size() == 5);
  CHECK(fine[2] == Approx(2.0));
}

TEST_CASE("a failed search has no hypothesis", "[calibrate][terra_hypotheses]") {
  terra::SearchResult s = search_with({candidate(10.0, 0.01)});
  s.status = terra::SearchStatus::no_overlap;
  CHECK(ulc::terra_hypotheses(s, 4, 10.0 * kDeg).empty());
}

TEST_CASE("the fallback takes the optima not yet tried, in the search's order, one per basin",
          "[calibrate][terra_hypotheses]") {
  const terra::SearchResult s =
      search_with({candidate(166.0, 0.004), candidate(8.0, 0.003), candidate(2.0, 0.005),
                   candidate(-60.0, 0.006), candidate(100.0, 0.006), candidate(-55.0, 0.007)});
  // Tried already: TERRA's best (8 deg) and something 3 deg from the 100-deg optimum.
  const std::vector<terra::RotationCandidate> tried{candidate(8.0, 0.003), candidate(103.0, 0.01)};
  const auto yaws = yaws_of(ulc::fallback_hypotheses(s, tried, 10, 10.0 * kDeg));
  // 2 deg is 8's basin, 100 deg is the tried 103's, -55 deg is -60's.
  REQUIRE(yaws.size() == 2);
  CHECK(yaws[0] == Approx(166.0));
  CHECK(yaws[1] == Approx(-60.0));
  CHECK(ulc::fallback_hypotheses(s, tried, 1, 10.0 * kDeg).size() == 1);
  CHECK(ulc::fallback_hypotheses(s, tried, 0, 10.0 * kDeg).empty());
  // Nothing tried yet: the same list as terra_hypotheses.
  const auto all = yaws_of(ulc::fallback_hypotheses(s, {}, 10, 10.0 * kDeg));
  CHECK(all == yaws_of(ulc::terra_hypotheses(s, 10, 10.0 * kDeg)));

  terra::SearchResult failed = s;
  failed.status = terra::SearchStatus::no_overlap;
  CHECK(ulc::fallback_hypotheses(failed, {}, 10, 10.0 * kDeg).empty());
}

TEST_CASE("a hypothesis near a confident ground vote starts from the vote's lever arm",
          "[calibrate][terra_hypotheses]") {
  ulc::calibrate_detail::TerraSearches searches;
  searches.kept = search_with({candidate(3.0, 1.0), candidate(120.0, 2.0)});
  ulc::MotionReport m;
  m.ok = true;
  m.method = "ground vote";
  m.rotation = yaw(1.0);
  m.vote.ok = true;
  m.vote.rotation = yaw(1.0);
  m.vote.translation = ulc::Vec3d(2.2, 0.5, 0.04);
  searches.motion = m;
  ulc::HypothesisOptions h;
  ulc::MotionFrameOptions o;  // vote_agree_deg 5: the search's 3 deg stands beside the vote
  const auto starts =
      ulc::calibrate_detail::start_rotations(searches, ulc::TerraSource::maps, h, o);
  REQUIRE(starts.candidates.size() >= 2);
  REQUIRE(starts.vote);
  // The search's answer (2 deg from the vote) starts from the vote's translation...
  CHECK(starts.start(0).linear().isApprox(yaw(3.0), 1e-12));
  CHECK(starts.start(0).translation().isApprox(m.vote.translation, 1e-12));
  // ...its other optimum, 119 deg away, from the origin.
  CHECK(starts.start(1).linear().isApprox(yaw(120.0), 1e-12));
  CHECK(starts.start(1).translation().isZero(0.0));

  // Not the vote's answer (the ground and travel's, or no confident vote): the origin.
  searches.motion->method = "ground and travel";
  const auto no_vote =
      ulc::calibrate_detail::start_rotations(searches, ulc::TerraSource::maps, h, o);
  CHECK_FALSE(no_vote.vote);
  CHECK(no_vote.start(0).translation().isZero(0.0));
}
