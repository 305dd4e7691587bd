// Hierarchy of one LiDAR: frames of a synthetic room with drifting poses come out closer to
// the truth, factors tie window anchors at every layer, the same bits on 1 and 2 threads.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "hots/hierarchy.hpp"
#include "hots_test_util.hpp"

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
}
