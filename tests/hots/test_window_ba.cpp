// Window bundle adjustment: perturbed poses of a synthetic window converge back to the truth,
// the plane extraction finds planes, results are identical on 1 and 2 threads.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "assembled_hessian.hpp"
#include "hots/window_ba.hpp"
#include "hots_test_util.hpp"
#include "ulc/core/pose_error.hpp"

using namespace hots;
using namespace hots_test;

namespace {

struct Window {
  std::vector<Isometry3d> truth;
  std::vector<std::vector<Vec3d>> frames;
};

const Window& window() {
  static const Window w = [] {
    Window out;
    out.truth = room_path(5, 0.6);
    for (auto& T : out.truth) T = Isometry3d(Eigen::Translation3d(300, -200, 10)) * T;
    // Moving the scene with the poses: the room is at the far origin too.
    const auto local = room_path(5, 0.6);
    out.frames = room_frames(local, 0.25, 0.01, 11);
    return out;
  }();
  return w;
}

std::vector<Isometry3d> disturbed(const std::vector<Isometry3d>& truth, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Isometry3d> out = truth;
  for (std::size_t i = 1; i < out.size(); ++i)
    out[i] = out[i] * ulc::se3_exp(random_vector6(rng, 0.05, 0.5 * kDeg));
  return out;
}

ulc::PoseError worst_relative(const std::vector<Isometry3d>& truth,
                              const std::vector<Isometry3d>& est) {
  ulc::PoseError worst;
  for (std::size_t i = 1; i < truth.size(); ++i) {
    const auto e = ulc::pose_error(Isometry3d(truth[0].inverse() * truth[i]),
                                   Isometry3d(est[0].inverse() * est[i]));
    worst.rotation_deg = std::max(worst.rotation_deg, e.rotation_deg);
    worst.translation_m = std::max(worst.translation_m, e.translation_m);
  }
  return worst;
}

template <typename S>
std::vector<std::vector<ulc::Vec3<S>>> as(const std::vector<std::vector<Vec3d>>& frames) {
  std::vector<std::vector<ulc::Vec3<S>>> out(frames.size());
  for (std::size_t f = 0; f < frames.size(); ++f)
    for (const Vec3d& p : frames[f]) out[f].push_back(p.cast<S>());
  return out;
}

}  // namespace

TEMPLATE_TEST_CASE("window BA brings perturbed poses back to the truth", "[hots][window_ba]", float,
                   double) {
  const Window& w = window();
  const auto frames = as<TestType>(w.frames);
  const auto start = disturbed(w.truth, 5);
  const auto e0 = worst_relative(w.truth, start);
  WindowBaOptions options;
  const WindowBaResult r = window_ba(frames, start, options);
  INFO(to_string(r.status) << ": " << r.reason << ", planes " << r.planes << ", iterations "
                           << r.iterations << ", cost " << r.initial_cost << " -> " << r.cost);
  REQUIRE(r.ok());
  CHECK(r.planes > 50);
  CHECK(r.cost < r.initial_cost);
  CHECK(r.poses[0].isApprox(start[0], 0.0));  // the gauge does not move
  const auto e = worst_relative(w.truth, r.poses);
  INFO("start " << e0.translation_m << " m " << e0.rotation_deg << " deg; result "
                << e.translation_m << " m " << e.rotation_deg << " deg; noise "
                << std::sqrt(r.noise_variance));
  CHECK(e0.translation_m > 0.03);
  CHECK(e.translation_m < 0.002);
  CHECK(e.rotation_deg < 0.01);
  // The noise estimate sees the 1 cm simulated noise.
  CHECK(std::sqrt(r.noise_variance) == Approx(0.01).epsilon(0.3));
  // At the optimum the gradient vanishes (for the free poses) and the Hessian there is
  // positive definite.
  const auto m = r.hessian.rows() - 6;
  CHECK(r.gradient.tail(m).norm() < 1e-6 * r.hessian.norm());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(r.hessian.bottomRightCorner(m, m));
  CHECK(eig.eigenvalues()(0) > 0.0);
}

TEST_CASE("window BA's Hessian is the sum of the planes' Hessians", "[hots][window_ba]") {
  // evaluate() sums each plane's cross terms as a rank-3 update and its own blocks apart; the
  // reference places evaluate_plane's dense Hessian (checked against central differences in
  // test_point_cluster) at the frames' blocks.
  const Window& w = window();
  const std::vector<Isometry3d> poses = disturbed(w.truth, 5);
  WindowBaOptions options;
  std::vector<const std::vector<Vec3d>*> clouds;
  for (const auto& f : w.frames) clouds.push_back(&f);
  const auto planes = extract_planes(clouds, poses, options.planes);
  REQUIRE(planes.size() > 20);
  const auto n = static_cast<Eigen::Index>(6 * poses.size());
  std::vector<Eigen::MatrixXd> to_frames;  // frame f's block of the variables
  for (std::size_t f = 0; f < poses.size(); ++f) {
    to_frames.push_back(Eigen::MatrixXd::Zero(6, n));
    to_frames.back().middleCols<6>(static_cast<Eigen::Index>(6 * f)).setIdentity();
  }
  const Eigen::MatrixXd reference = assembled_hessian(planes, poses, options.evaluation, to_frames);
  const auto sums = window_ba_detail::evaluate(planes, poses, options);
  CHECK((sums.H - reference).norm() <= 1e-9 * reference.norm());
  CHECK(reference.norm() > 0.0);
}

TEST_CASE("window BA gives the same bits on 1 and 2 threads", "[hots][window_ba]") {
  const Window& w = window();
  const auto start = disturbed(w.truth, 8);
  WindowBaOptions options;
  options.grain = 8;
  WindowBaResult one, two;
  tbb::task_arena(1).execute([&] { one = window_ba(w.frames, start, options); });
  tbb::task_arena(2).execute([&] { two = window_ba(w.frames, start, options); });
  REQUIRE(one.ok());
  CHECK(one.planes == two.planes);
  CHECK(one.iterations == two.iterations);
  CHECK(one.cost == two.cost);
  for (std::size_t i = 0; i < one.poses.size(); ++i)
    CHECK(one.poses[i].matrix() == two.poses[i].matrix());
  CHECK(one.hessian == two.hessian);
}

TEST_CASE("window BA reports unusable input", "[hots][window_ba]") {
  const Window& w = window();
  std::vector<std::vector<Vec3d>> one_frame{w.frames[0]};
  CHECK(window_ba(one_frame, {w.truth[0]}).status == WindowBaStatus::invalid_input);
  std::vector<std::vector<Vec3d>> tiny{{Vec3d(0, 0, 0)}, {Vec3d(1, 0, 0)}};
  CHECK(window_ba(tiny, {w.truth[0], w.truth[1]}).status == WindowBaStatus::too_few_planes);
  auto bad = w.truth;
  bad[2](0, 3) = std::nan("");
  CHECK(window_ba(w.frames, bad).status == WindowBaStatus::invalid_input);
}
