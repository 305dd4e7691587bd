// The second look at a refusal for the off-ground overlap alone (jeep/second_look.hpp): a fit
// that every start of the paper's disturbance comes back to passes; a fit that leaves a
// direction free, or that the two registration directions disagree on, does not.
#include <catch2/catch.hpp>
#include <random>
#include <string>
#include <vector>

#include "jeep/second_look.hpp"
#include "jeep/two_way.hpp"
#include "surface_samples.hpp"

namespace {

using jeep_test::add_rectangle;
using Points = jeep_test::SurfacePoints;
using ulc::Isometry3d;

using jeep_test::kX;
using jeep_test::kY;
using jeep_test::kZ;

/// 40 x 40 m of ground and a 4 m wall facing x at x = 10; with `closed`, also walls facing y at
/// y = 8 and y = -12 and a 2 m box, so that every direction is pinned.
Points street(bool closed, double phase, std::mt19937& rng) {
  Points p;
  const double step = 0.25;
  add_rectangle(p, {-20, -20, 0}, kX, 40, kY, 40, step, phase, rng);
  add_rectangle(p, {10, -20, 0}, kY, 40, kZ, 4, step, phase, rng);
  if (closed) {
    add_rectangle(p, {-20, 8, 0}, kX, 30, kZ, 4, step, phase, rng);
    add_rectangle(p, {-20, -12, 0}, kX, 14, kZ, 3, step, phase, rng);
    add_rectangle(p, {-4, -2, 0}, kX, 2, kZ, 2, step, phase, rng);
    add_rectangle(p, {-4, -2, 0}, kY, 2, kZ, 2, step, phase, rng);
  }
  return p;
}

struct Look {
  jeep::TwoWayResult two_way;
  jeep::SecondLookReport report;
};

jeep::SecondLookOptions enabled() {
  jeep::SecondLookOptions o;
  o.enabled = true;
  return o;
}

Look look_at(const Points& a, const Points& b, const jeep::SecondLookOptions& options = enabled()) {
  const auto stages = jeep::default_map_registration();
  Look out;
  out.two_way = jeep::two_way_extrinsic(a, b, Isometry3d::Identity(), stages);
  out.report = jeep::second_look(b, jeep::map_target(a, stages), Isometry3d::Identity(),
                                 out.two_way, stages, jeep::StartSearchOptions{}, options);
  return out;
}

}  // namespace

TEST_CASE("the second look passes a fit every start comes back to", "[jeep][second_look]") {
  std::mt19937 rng(5);
  const Points a = street(true, 0.0, rng), b = street(true, 0.12, rng);
  const Look l = look_at(a, b);
  INFO(l.report.reason << "; returned " << l.report.returned << " of " << l.report.starts
                       << ", gap " << l.two_way.gap_translation << " m");
  REQUIRE(l.two_way.applied);
  CHECK(l.report.ran);
  CHECK(l.report.starts == 12);
  CHECK(l.report.returned == 12);
  CHECK(l.report.passed);
}

TEST_CASE("the second look refuses a fit that leaves a direction free", "[jeep][second_look]") {
  std::mt19937 rng(9);
  // Ground and one wall: nothing holds the maps along the wall, so the starts shifted or
  // turned along it end wherever their first stage left them.
  // (The two-way step calls such a pair degenerate; the directions are taken as agreeing
  // here, to look at the basin test alone.)
  const Points a = street(false, 0.0, rng), b = street(false, 0.12, rng);
  const auto stages = jeep::default_map_registration();
  jeep::TwoWayResult agreeing;
  agreeing.applied = true;
  const auto r = jeep::second_look(b, jeep::map_target(a, stages), Isometry3d::Identity(), agreeing,
                                   stages, jeep::StartSearchOptions{}, jeep::SecondLookOptions{});
  INFO(r.reason << "; returned " << r.returned << " of " << r.starts);
  CHECK(r.ran);
  CHECK(r.starts == 12);
  CHECK(r.returned < jeep::SecondLookOptions{}.min_returned);
  CHECK_FALSE(r.passed);
  CHECK(std::string(r.reason).find("do not come back") != std::string::npos);
}

TEST_CASE("the second look needs both directions to agree", "[jeep][second_look]") {
  std::mt19937 rng(13);
  const Points a = street(true, 0.0, rng), b = street(true, 0.12, rng);
  const auto stages = jeep::default_map_registration();
  const auto planes = jeep::map_target(a, stages);
  jeep::TwoWayResult two_way;
  two_way.applied = true;
  two_way.gap_translation = 0.03;  // more than max_gap_translation
  auto r = jeep::second_look(b, planes, Isometry3d::Identity(), two_way, stages,
                             jeep::StartSearchOptions{}, jeep::SecondLookOptions{});
  CHECK_FALSE(r.passed);
  CHECK(r.starts == 0);  // refused before any registration
  CHECK(std::string(r.reason).find("disagree") != std::string::npos);

  two_way.gap_translation = 0.0;
  two_way.gap_rotation = 0.2 * 3.14159265358979323846 / 180.0;
  r = jeep::second_look(b, planes, Isometry3d::Identity(), two_way, stages,
                        jeep::StartSearchOptions{}, jeep::SecondLookOptions{});
  CHECK_FALSE(r.passed);

  two_way = jeep::TwoWayResult{};  // not applied: the backward registration failed
  r = jeep::second_look(b, planes, Isometry3d::Identity(), two_way, stages,
                        jeep::StartSearchOptions{}, jeep::SecondLookOptions{});
  CHECK_FALSE(r.passed);
  CHECK(std::string(r.reason).find("one failed") != std::string::npos);
}

TEST_CASE("only a refusal for the off-ground overlap alone gets a second look",
          "[jeep][second_look]") {
  const jeep::AcceptanceOptions rule;
  const jeep::SecondLookOptions options = enabled();
  jeep::AcceptanceReport r;
  r.agreeing = rule.min_agreeing;
  r.condition = rule.min_condition;
  r.directional_overlap = rule.min_directional_overlap;
  r.off_ground_overlap = 0.5 * (options.min_off_ground_overlap + rule.min_off_ground_overlap);
  CHECK(jeep::qualifies_for_second_look(r, rule, options));

  jeep::AcceptanceReport ground = r;  // refused for the ground itself: no second look
  ground.directional_overlap = 0.5 * rule.min_directional_overlap;
  CHECK_FALSE(jeep::qualifies_for_second_look(ground, rule, options));

  jeep::AcceptanceReport accepted = r;
  accepted.accepted = true;
  CHECK_FALSE(jeep::qualifies_for_second_look(accepted, rule, options));

  jeep::AcceptanceReport too_low = r;
  too_low.off_ground_overlap = 0.5 * options.min_off_ground_overlap;
  CHECK_FALSE(jeep::qualifies_for_second_look(too_low, rule, options));

  jeep::AcceptanceReport few = r;
  few.agreeing = rule.min_agreeing - 1;
  CHECK_FALSE(jeep::qualifies_for_second_look(few, rule, options));

  jeep::AcceptanceReport loose = r;
  loose.condition = 0.5 * rule.min_condition;
  CHECK_FALSE(jeep::qualifies_for_second_look(loose, rule, options));

  CHECK_FALSE(jeep::qualifies_for_second_look(r, rule, jeep::SecondLookOptions{}));  // opt-in
}
