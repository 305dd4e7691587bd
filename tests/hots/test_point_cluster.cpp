// Point clusters: sums against brute force, the plane cost's gradient and Hessian against
// central differences, invariance to a common rigid motion, the degenerate guard.
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "hots/point_cluster.hpp"
#include "hots_test_util.hpp"

using namespace hots;
using hots_test::random_pose;

namespace {

/// Three frames seeing one noisy, slightly curved patch near `centre`, in their body frames.
template <typename S>
struct PlaneScene {
  std::vector<Isometry3d> poses;
  std::vector<FrameCluster> frames;
  std::vector<std::vector<ulc::Vec3<S>>> body_points;
  Vec3d centre;
};

template <typename S>
PlaneScene<S> make_scene(std::uint64_t seed, const Vec3d& centre, std::size_t n_frames = 3) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  PlaneScene<S> s;
  s.centre = centre;
  const Vec3d normal = Vec3d(0.3, -0.2, 1.0).normalized();
  const Vec3d t1 = normal.unitOrthogonal();
  const Vec3d t2 = normal.cross(t1);
  for (std::size_t f = 0; f < n_frames; ++f) {
    // Poses slightly wrong, so the cost is not at its minimum (the Hessian's first-order
    // terms matter).
    const Isometry3d T = random_pose(rng, 0.4, 3.0) * Isometry3d(Eigen::Translation3d(centre));
    s.poses.push_back(T);
    FrameCluster fc;
    fc.frame = f;
    std::vector<ulc::Vec3<S>> pts;
    for (int i = 0; i < 40; ++i) {
      const double a = 2 * uni(rng), b = 1.5 * uni(rng);
      const Vec3d world = centre + a * t1 + b * t2 + (noise(rng) + 0.05 * a * a) * normal;
      const ulc::Vec3<S> body = (T.inverse() * world).cast<S>();
      pts.push_back(body);
    }
    // Added from the stored points: GCC 12 at -O3 may otherwise hand add() the unrounded
    // double value of a float point it still holds in a register.
    for (const auto& p : pts) fc.cluster.add(p);
    // The true world placement was perturbed after sampling: the frames disagree a little.
    std::mt19937_64 rng2(seed * 7 + f);
    s.poses[f] = ulc::se3_exp(Vec6d(hots_test::random_vector6(rng2, 0.02, 0.01))) * T;
    s.frames.push_back(fc);
    s.body_points.push_back(pts);
  }
  return s;
}

}  // namespace

TEMPLATE_TEST_CASE("cluster sums and their transform match brute force", "[hots][cluster]", float,
                   double) {
  const auto s = make_scene<TestType>(3, Vec3d(40, -25, 3));
  for (std::size_t f = 0; f < s.frames.size(); ++f) {
    const Isometry3d& T = s.poses[f];
    const Vec3d c(41, -24, 2.5);
    const PointCluster moved = s.frames[f].cluster.transformed(T, c);
    Mat3d outer = Mat3d::Zero();
    Vec3d sum = Vec3d::Zero();
    std::vector<Vec3d> world;
    for (const auto& p : s.body_points[f]) {
      const Vec3d x = T * p.template cast<double>() - c;
      outer += x * x.transpose();
      sum += x;
      world.push_back(x + c);
    }
    CHECK(moved.count == Approx(static_cast<double>(world.size())));
    CHECK((moved.sum - sum).norm() < 1e-9);
    CHECK((moved.sum_outer - outer).norm() < 1e-8);
    Vec3d mean = sum / static_cast<double>(world.size());
    Mat3d scatter = Mat3d::Zero();
    for (const Vec3d& x : world) scatter += (x - c - mean) * (x - c - mean).transpose();
    CHECK((moved.scatter() - scatter).norm() < 1e-9);
    CHECK((moved.mean() - (mean + c)).norm() < 1e-10);
  }
}

TEMPLATE_TEST_CASE("plane cost is the squared distance to the best plane", "[hots][cluster]", float,
                   double) {
  const auto s = make_scene<TestType>(5, Vec3d(-30, 12, 1));
  std::vector<Vec3d> world;
  for (std::size_t f = 0; f < s.frames.size(); ++f)
    for (const auto& p : s.body_points[f]) world.push_back(s.poses[f] * p.template cast<double>());
  Vec3d mean = Vec3d::Zero();
  for (const Vec3d& x : world) mean += x;
  mean /= static_cast<double>(world.size());
  Mat3d scatter = Mat3d::Zero();
  for (const Vec3d& x : world) scatter += (x - mean) * (x - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Mat3d> solver(scatter);
  const Vec3d n = solver.eigenvectors().col(0);
  double sq = 0;
  for (const Vec3d& x : world) sq += std::pow(n.dot(x - mean), 2);
  CHECK(plane_cost(s.frames, s.poses, s.centre) == Approx(sq).epsilon(1e-9));
  // Any anchor gives the same cost.
  CHECK(plane_cost(s.frames, s.poses, Vec3d::Zero()) == Approx(sq).epsilon(1e-7));
}

TEST_CASE("plane gradient and Hessian match central differences", "[hots][cluster]") {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const auto s = make_scene<double>(seed, Vec3d(25.0 * seed, -10, 2), 2 + seed);
    const PlaneDerivatives d = evaluate_plane(s.frames, s.poses, s.centre);
    REQUIRE_FALSE(d.degenerate);
    CHECK(d.cost == Approx(plane_cost(s.frames, s.poses, s.centre)).epsilon(1e-12));
    const std::size_t K = s.frames.size();
    const auto n = static_cast<Eigen::Index>(6 * K);
    // F(x) = cost with every pose perturbed, T_a <- exp(x_a) T_a: its derivatives at x = 0.
    auto F = [&](const Eigen::VectorXd& x) {
      std::vector<Isometry3d> poses = s.poses;
      for (std::size_t a = 0; a < K; ++a)
        poses[a] = ulc::se3_exp(Vec6d(x.segment<6>(static_cast<Eigen::Index>(6 * a)))) * poses[a];
      return plane_cost(s.frames, poses, s.centre);
    };
    const double h = 1e-5, h2 = 2e-4;
    Eigen::VectorXd g_fd(n);
    Eigen::MatrixXd H_fd(n, n);
    for (Eigen::Index r = 0; r < n; ++r) {
      const Eigen::VectorXd er = Eigen::VectorXd::Unit(n, r);
      g_fd[r] = (F(h * er) - F(-h * er)) / (2 * h);
      for (Eigen::Index c = 0; c < n; ++c) {
        const Eigen::VectorXd ec = Eigen::VectorXd::Unit(n, c);
        H_fd(r, c) =
            (F(h2 * (er + ec)) - F(h2 * (er - ec)) - F(h2 * (ec - er)) + F(-h2 * (er + ec))) /
            (4 * h2 * h2);
      }
    }
    INFO("seed " << seed << " cost " << d.cost);
    CHECK((d.gradient - g_fd).norm() <= 1e-6 * (1.0 + g_fd.norm()));
    CHECK((d.hessian - H_fd).norm() <= 1e-4 * (1.0 + H_fd.norm()));
    CHECK((d.hessian - d.hessian.transpose()).norm() <= 1e-9 * d.hessian.norm());
  }
}

TEST_CASE("plane cost and gradient are invariant to a common rigid motion", "[hots][cluster]") {
  const auto s = make_scene<double>(9, Vec3d(5, 60, -2));
  std::mt19937_64 rng(17);
  const Isometry3d W = random_pose(rng, 2.0, 100.0);
  std::vector<Isometry3d> moved;
  for (const auto& T : s.poses) moved.push_back(W * T);
  const double f0 = plane_cost(s.frames, s.poses, s.centre);
  const double f1 = plane_cost(s.frames, moved, W * s.centre);
  CHECK(f1 == Approx(f0).epsilon(1e-9));
  // The same small motion applied to every pose changes nothing: the gradient is orthogonal to
  // it and the Hessian maps it to zero.
  const PlaneDerivatives d = evaluate_plane(s.frames, s.poses, s.centre);
  const std::size_t K = s.frames.size();
  Vec6d xi;
  xi << 0.3, -0.2, 0.5, 0.01, -0.02, 0.015;
  Eigen::VectorXd common(6 * K);
  for (std::size_t a = 0; a < K; ++a) common.segment<6>(static_cast<Eigen::Index>(6 * a)) = xi;
  CHECK(std::abs(d.gradient.dot(common)) <= 1e-9 * d.gradient.norm() * common.norm());
  // Along a common motion the cost is constant, so its second derivative there vanishes too.
  CHECK(std::abs(common.dot(d.hessian * common)) <=
        1e-7 * (d.hessian.norm() * common.squaredNorm() + 1.0));
}

TEST_CASE("a cluster with no plane direction is reported degenerate", "[hots][cluster]") {
  // Points on the three axes, symmetric: the scatter is a multiple of the identity.
  FrameCluster f;
  for (double s : {-1.0, 1.0}) {
    f.cluster.add(Vec3d(s, 0, 0));
    f.cluster.add(Vec3d(0, s, 0));
    f.cluster.add(Vec3d(0, 0, s));
  }
  const std::vector<FrameCluster> frames{f};
  const std::vector<Isometry3d> poses{Isometry3d::Identity()};
  const PlaneDerivatives d = evaluate_plane(frames, poses, Vec3d::Zero());
  CHECK(d.degenerate);
  CHECK(d.gradient.isZero(0.0));
}
