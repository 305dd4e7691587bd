// The NDT refinement baseline of bench_jeep (bench/ndt_baseline.hpp) on the synthetic room of
// room_scene.hpp, the source placed by a known pose. NDT must stay at the truth when started
// there and reach it from the refinement table's 5 deg / 2 m kind of start; its analytic
// gradient and Hessian must match finite differences of its score; one and two threads must give
// the same bits; too few points must be refused.
#include <catch2/catch.hpp>

#include <tbb/task_arena.h>

#include "../../bench/ndt_baseline.hpp"
#include "room_scene.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/pose_error.hpp"

namespace {

using room_scene::pose;
using room_scene::Scene;
using ulc::Isometry3d;

/// The score at exp(h e_k) T over cells held at T, for finite differences.
double score_moved(const Scene& s, const ndt_baseline::Grid& grid,
                   const std::vector<ndt_baseline::detail::CellList>& cells, const Isometry3d& T,
                   const ndt_baseline::ScoreConstants& k, int axis, double h) {
  ulc::Vec6d xi = ulc::Vec6d::Zero();
  xi[axis] = h;
  return ndt_baseline::score(s.source, grid, cells, ulc::se3_exp(xi) * T, k);
}

}  // namespace

TEST_CASE("NDT stays at the pose between two samplings of a room when started there",
          "[bench][ndt]") {
  const Scene s;
  const auto r = ndt_baseline::ndt(s.source, s.target, s.truth);
  const auto e = ulc::pose_error(s.truth, r.pose);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m, " << r.iterations
                << " iterations, " << r.scored << " of " << s.source.size() << " scored");
  CHECK(r.converged);
  CHECK(e.rotation_deg < 0.1);
  CHECK(e.translation_m < 0.01);
  CHECK(r.scored > s.source.size() / 2);
}

TEST_CASE("NDT recovers the pose from a 5 deg / 2 m start", "[bench][ndt]") {
  const Scene s;
  const Isometry3d start = pose(5.0, {-2, 1, 1}, {1.6, 1.0, 0.6}) * s.truth;
  REQUIRE(ulc::pose_error(s.truth, start).translation_m > 1.9);
  const auto r = ndt_baseline::ndt(s.source, s.target, start);
  const auto e = ulc::pose_error(s.truth, r.pose);
  INFO("e_rot " << e.rotation_deg << " deg, e_trans " << e.translation_m << " m, " << r.iterations
                << " iterations");
  CHECK(r.converged);
  CHECK(e.rotation_deg < 0.1);
  CHECK(e.translation_m < 0.01);
}

TEST_CASE("NDT's gradient and Hessian match finite differences of its score", "[bench][ndt]") {
  const Scene s;
  const Isometry3d T = pose(1.5, {1, -1, 2}, {0.15, -0.1, 0.05}) * s.truth;  // not optimal
  const auto grid = ndt_baseline::build_grid(s.target, 1.0);
  const auto k = ndt_baseline::score_constants(1.0, ndt_baseline::Options{}.outlier_ratio);
  const auto cells = ndt_baseline::detail::associate(s.source, grid, T);
  ulc::Vec6d g;
  ulc::Mat6d H;
  ndt_baseline::derivatives(s.source, grid, cells, T, k, g, H);
  REQUIRE(g.norm() > 1.0);  // far enough from the minimum for the check to mean something
  const double h = 1e-5;
  ulc::Vec6d g_fd;
  ulc::Mat6d H_fd;
  const double f0 = ndt_baseline::score(s.source, grid, cells, T, k);
  for (int a = 0; a < 6; ++a) {
    const double fp = score_moved(s, grid, cells, T, k, a, h);
    const double fm = score_moved(s, grid, cells, T, k, a, -h);
    g_fd[a] = (fp - fm) / (2 * h);
    H_fd(a, a) = (fp - 2 * f0 + fm) / (h * h);
  }
  for (int a = 0; a < 6; ++a)  // mixed second derivatives: four-point formula
    for (int b = 0; b < 6; ++b) {
      if (a == b) continue;
      ulc::Vec6d xi = ulc::Vec6d::Zero();
      double f[4];
      for (int q = 0; q < 4; ++q) {
        xi.setZero();
        xi[a] = (q & 1) ? -h : h;
        xi[b] = (q & 2) ? -h : h;
        f[q] = ndt_baseline::score(s.source, grid, cells, ulc::se3_exp(xi) * T, k);
      }
      H_fd(a, b) = (f[0] - f[1] - f[2] + f[3]) / (4 * h * h);
    }
  INFO("g " << g.transpose() << "\ng_fd " << g_fd.transpose() << "\nH\n"
            << H << "\nH_fd\n"
            << H_fd);
  CHECK((g - g_fd).norm() < 1e-5 * g.norm());
  CHECK((H - H_fd).norm() < 1e-3 * H.norm());
}

TEST_CASE("NDT gives the same bits on one and on two threads", "[bench][ndt]") {
  const Scene s;
  const Isometry3d start = pose(3.0, {0, 1, 1}, {0.5, -0.3, 0.2}) * s.truth;
  const auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    return arena.execute([&] { return ndt_baseline::ndt(s.source, s.target, start); });
  };
  const auto one = run(1), two = run(2);
  CHECK(one.pose.matrix() == two.pose.matrix());
  CHECK(one.iterations == two.iterations);
  CHECK(one.score == two.score);
}

TEST_CASE("NDT refuses clouds with fewer points than it needs to score", "[bench][ndt]") {
  const Scene s;
  const ndt_baseline::Points few(s.source.begin(), s.source.begin() + 10);
  const auto r = ndt_baseline::ndt(few, s.target, Isometry3d::Identity());
  CHECK_FALSE(r.converged);
  CHECK(r.iterations == 0);
}
