// Hierarchy of one LiDAR: frames of a synthetic room with drifting poses come out closer to
// the truth, factors tie window anchors at every layer, bridges tie the top layer's submaps,
// the same bits on 1 and 2 threads.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "hots/boundary_bridges.hpp"
#include "hots/hierarchy.hpp"
#include "hots_test_util.hpp"
#include "ulc/core/pose_error.hpp"

using namespace hots;
using namespace hots_test;

namespace {

struct Scene {
  std::vector<Isometry3d> truth, start;
  std::vector<std::vector<Eigen::Vector3f>> frames;
};

const Scene& scene() {
  static const Scene s = [] {
    Scene out;
    out.truth = room_path(12, 0.5, -10.0);
    const auto frames = room_frames(out.truth, 0.3, 0.01, 21);
    for (const auto& f : frames) {
      out.frames.emplace_back();
      for (const Vec3d& p : f) out.frames.back().push_back(p.cast<float>());
    }
    std::mt19937_64 rng(4);
    out.start = out.truth;
    for (std::size_t k = 1; k < out.start.size(); ++k)
      out.start[k] =
          out.start[k] *
          ulc::se3_exp(Vec6d(static_cast<double>(k) * random_vector6(rng, 0.01, 0.1 * kDeg)));
    return out;
  }();
  return s;
}

double worst_relative_to_first(const std::vector<Isometry3d>& truth,
                               const std::vector<Isometry3d>& est) {
  double w = 0;
  for (std::size_t k = 1; k < truth.size(); ++k)
    w = std::max(w, ((truth[0].inverse() * truth[k]).translation() -
                     (est[0].inverse() * est[k]).translation())
                        .norm());
  return w;
}

}  // namespace

TEST_CASE("the hierarchy refines drifting poses and ties windows at every layer",
          "[hots][hierarchy]") {
  const Scene& s = scene();
  HierarchyOptions options;
  options.window = 3;
  const auto h = build_hierarchy(s.frames, s.start, options);
  CHECK(h.failed_windows == 0);
  // 12 frames -> 4 submaps -> 2 (a window of 3 and a single carried up) -> 1.
  CHECK(h.windows == 4 + 1 + 1);
  REQUIRE(h.members.size() == 4);
  CHECK(h.members[1].size() == 4);
  CHECK(h.members[3].size() == 1);
  CHECK(h.members[3][0].begin == 0);
  CHECK(h.members[3][0].end == 12);
  // Two factors per window of 3, one per window of 2.
  CHECK(h.factors.size() == 8 + 2 + 1);
  for (const auto& f : h.factors) {
    const Eigen::SelfAdjointEigenSolver<Mat6d> eig(f.information);
    CHECK(eig.eigenvalues()(0) > 0.0);
    CHECK(f.from < f.to);
  }
  const double before = worst_relative_to_first(s.truth, s.start);
  const double after = worst_relative_to_first(s.truth, h.poses);
  INFO("worst translation relative to the first frame: " << before << " -> " << after);
  CHECK(before > 0.05);
  CHECK(after < 0.005);
}

TEST_CASE("the hierarchy gives the same bits on 1 and 2 threads", "[hots][hierarchy]") {
  const Scene& s = scene();
  HierarchyOptions options;
  options.window = 4;
  options.layers = 2;
  HierarchyResult<float> one, two;
  tbb::task_arena(1).execute([&] { one = build_hierarchy(s.frames, s.start, options); });
  tbb::task_arena(2).execute([&] { two = build_hierarchy(s.frames, s.start, options); });
  REQUIRE(one.factors.size() == two.factors.size());
  for (std::size_t k = 0; k < one.poses.size(); ++k)
    CHECK(one.poses[k].matrix() == two.poses[k].matrix());
  for (std::size_t k = 0; k < one.factors.size(); ++k)
    CHECK(one.factors[k].information == two.factors[k].information);
  options.layers = 1;  // three top submaps: two bridges
  BoundaryBridges bridges_one, bridges_two;
  tbb::task_arena(1).execute([&] {
    bridges_one = boundary_bridges(build_hierarchy(s.frames, s.start, options), s.frames, options);
  });
  tbb::task_arena(2).execute([&] {
    bridges_two = boundary_bridges(build_hierarchy(s.frames, s.start, options), s.frames, options);
  });
  REQUIRE(bridges_one.factors.size() == 2 * 2);
  REQUIRE(bridges_two.factors.size() == bridges_one.factors.size());
  for (std::size_t k = 0; k < bridges_one.factors.size(); ++k) {
    CHECK(bridges_one.factors[k].measured.matrix() == bridges_two.factors[k].measured.matrix());
    CHECK(bridges_one.factors[k].information == bridges_two.factors[k].information);
  }
}

TEST_CASE("bridges tie the top layer's submaps across their boundaries", "[hots][hierarchy]") {
  // One layer of windows of 3 over 12 frames: top submaps [0,3) [3,6) [6,9) [9,12), tied to
  // each other only by the start's (drifting) steps. A bridge over frames [b-1, b+2) measures
  // the step across boundary b from both sides' points.
  const Scene& s = scene();
  HierarchyOptions options;
  options.window = 3;
  options.layers = 1;
  const auto h = build_hierarchy(s.frames, s.start, options);
  REQUIRE(h.members.size() == 2);
  REQUIRE(h.members.back().size() == 4);
  const BoundaryBridges bridges = boundary_bridges(h, s.frames, options);
  CHECK(bridges.windows == 3);
  CHECK(bridges.planes > 0);
  REQUIRE(bridges.bridged.size() == 3);
  for (const bool b : bridges.bridged) CHECK(b);
  REQUIRE(bridges.factors.size() == 3 * 2);  // to the far side's two frames
  for (std::size_t k = 0; k < bridges.factors.size(); ++k) {
    const HierarchyFactor& f = bridges.factors[k];
    const std::size_t boundary = 3 * (k / 2 + 1);
    CHECK(f.from == boundary - 1);
    CHECK(f.to == boundary + k % 2);
    const Eigen::SelfAdjointEigenSolver<Mat6d> eig(f.information);
    CHECK(eig.eigenvalues()(0) > 0.0);
    const Isometry3d truth = s.truth[f.from].inverse() * s.truth[f.to];
    const auto before = ulc::pose_error(truth, h.poses[f.from].inverse() * h.poses[f.to]);
    const auto after = ulc::pose_error(truth, f.measured);
    INFO("factor " << f.from << " -> " << f.to << ": " << 100 * before.translation_m << " cm "
                   << before.rotation_deg << " deg -> " << 100 * after.translation_m << " cm "
                   << after.rotation_deg << " deg");
    CHECK(before.translation_m > 0.01);
    CHECK(after.translation_m < 0.2 * before.translation_m);
    CHECK(after.rotation_deg < 0.2 * before.rotation_deg);
  }
  // A single top submap has no boundary; a bridge never runs.
  HierarchyOptions tall = options;
  tall.layers = 3;
  const auto one_top = build_hierarchy(s.frames, s.start, tall);
  REQUIRE(one_top.members.back().size() == 1);
  const BoundaryBridges none = boundary_bridges(one_top, s.frames, tall);
  CHECK(none.bridged.empty());
  CHECK(none.factors.empty());
  CHECK(none.windows == 0);
}

TEST_CASE("the hierarchy reports its windows as they finish, and stops when the hook throws",
          "[hots][hierarchy][progress]") {
  const Scene& s = scene();
  HierarchyOptions options;
  options.window = 2;
  options.layers = 4;  // 12 frames: 6 + 3 + 2 + 1 windows
  std::vector<double> seen;
  HierarchyResult<float> with, without;
  tbb::task_arena(1).execute([&] {
    with = build_hierarchy<float>(s.frames, s.start, options, nullptr,
                                  [&](double f) { seen.push_back(f); });
    without = build_hierarchy(s.frames, s.start, options);
  });
  // One thread: batches of 4 windows, so layer 0 reports twice (4 and 6 of 12 windows).
  REQUIRE(seen.size() == 5);
  CHECK(seen.front() == Approx(4.0 / 12.0));
  for (std::size_t k = 1; k < seen.size(); ++k) CHECK(seen[k] > seen[k - 1]);
  CHECK(seen.back() == Approx(1.0));
  // Reporting changes nothing in the result.
  REQUIRE(with.poses.size() == without.poses.size());
  for (std::size_t k = 0; k < with.poses.size(); ++k)
    CHECK(with.poses[k].matrix() == without.poses[k].matrix());
  CHECK(with.factors.size() == without.factors.size());
  // A hook that throws (Ctrl-C from Python) ends the build at the next report.
  struct Stop {};
  int calls = 0;
  CHECK_THROWS_AS(build_hierarchy<float>(s.frames, s.start, options, nullptr,
                                         [&](double) {
                                           ++calls;
                                           throw Stop{};
                                         }),
                  Stop);
  CHECK(calls == 1);
}
