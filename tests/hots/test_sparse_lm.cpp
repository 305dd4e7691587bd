// Pose graph and sparse LM: factor Jacobians against central differences, a 1000-pose loop
// solved to the known answer, agreement with a dense Gauss-Newton on a small noisy graph, a
// noisy graph ending closer to the truth than its start, and identical bits on 1 and 2 threads.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "hots/sparse_lm.hpp"
#include "hots_test_util.hpp"
#include "ulc/core/pose_error.hpp"

using namespace hots;
using namespace hots_test;

namespace {

/// Poses around a circle of radius r, with a little climb and wobble.
std::vector<Isometry3d> circle(std::size_t n, double r) {
  std::vector<Isometry3d> out;
  for (std::size_t k = 0; k < n; ++k) {
    const double a = 2.0 * 3.14159265358979323846 * static_cast<double>(k) / static_cast<double>(n);
    Isometry3d T = Isometry3d::Identity();
    T.translation() = Vec3d(r * std::cos(a), r * std::sin(a), 0.5 * std::sin(3 * a));
    T.linear() = ulc::so3_exp(Vec3d(0.05 * std::sin(5 * a), 0.03 * std::cos(2 * a), a));
    out.push_back(T);
  }
  return out;
}

PoseFactor between(std::size_t i, std::size_t j, const Isometry3d& Z, double st, double sr) {
  PoseFactor f;
  f.from = i;
  f.to = j;
  f.measured = Z;
  f.sqrt_information = isotropic_sqrt_information(st, sr);
  return f;
}

/// A loop: odometry between neighbours, closures every `closure` poses across the circle,
/// measurements from `truth` with optional noise; variables start at `start`.
PoseGraph loop_graph(const std::vector<Isometry3d>& truth, const std::vector<Isometry3d>& start,
                     double noise_t, double noise_r, std::uint64_t seed, std::size_t closure) {
  std::mt19937_64 rng(seed);
  PoseGraph g;
  for (std::size_t k = 0; k < start.size(); ++k) g.add_variable(start[k], k == 0);
  const std::size_t n = truth.size();
  auto add = [&](std::size_t i, std::size_t j) {
    const Isometry3d Z =
        ulc::se3_exp(random_vector6(rng, noise_t, noise_r)) * (truth[i].inverse() * truth[j]);
    g.add_factor(between(i, j, Z, 0.01 + noise_t, 0.001 + noise_r));
  };
  for (std::size_t k = 0; k + 1 < n; ++k) add(k, k + 1);
  add(n - 1, 0);
  for (std::size_t k = 0; k < n; k += closure) add(k, (k + n / 2) % n);
  return g;
}

std::vector<Isometry3d> drifted(const std::vector<Isometry3d>& truth, std::uint64_t seed,
                                double sigma_t, double sigma_r) {
  std::mt19937_64 rng(seed);
  std::vector<Isometry3d> out = truth;
  for (std::size_t k = 1; k < out.size(); ++k)
    out[k] = ulc::se3_exp(random_vector6(rng, sigma_t, sigma_r)) * out[k];
  return out;
}

double worst_translation(const std::vector<Isometry3d>& a, const std::vector<Isometry3d>& b) {
  double w = 0;
  for (std::size_t k = 0; k < a.size(); ++k)
    w = std::max(w, (a[k].translation() - b[k].translation()).norm());
  return w;
}

double rms_translation(const std::vector<Isometry3d>& a, const std::vector<Isometry3d>& b) {
  double s = 0;
  for (std::size_t k = 0; k < a.size(); ++k)
    s += (a[k].translation() - b[k].translation()).squaredNorm();
  return std::sqrt(s / static_cast<double>(a.size()));
}

}  // namespace

TEST_CASE("pose factor Jacobians match central differences", "[hots][pose_graph]") {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<Isometry3d> vars{random_pose(rng, 2.5, 40.0), random_pose(rng, 2.5, 40.0),
                                 random_pose(rng, 2.5, 3.0)};
    PoseFactor f;
    f.from = 0;
    f.to = 1;
    f.measured = random_pose(rng, 1.0, 5.0);
    if (trial % 2) {  // the extrinsic kind: an offset and a measurement variable
      f.from_offset = random_pose(rng, 0.2, 1.0);
      f.measured_var = 2;
    }
    const FactorLinearization lin = linearize_factor(f, vars);
    const double h = 1e-6;
    for (std::size_t v = 0; v < 3; ++v) {
      const Mat6d& J = v == 0 ? lin.J_from : v == 1 ? lin.J_to : lin.J_measured;
      Mat6d fd;
      for (int i = 0; i < 6; ++i) {
        Vec6d d = Vec6d::Zero();
        d[i] = h;
        auto plus = vars, minus = vars;
        plus[v] = ulc::se3_exp(d) * vars[v];
        minus[v] = ulc::se3_exp(Vec6d(-d)) * vars[v];
        fd.col(i) = (linearize_factor(f, plus, false).residual -
                     linearize_factor(f, minus, false).residual) /
                    (2 * h);
      }
      INFO("trial " << trial << " variable " << v);
      CHECK((J - fd).norm() <= 1e-6 * (1.0 + fd.norm()));
    }
  }
}

TEST_CASE("sparse LM solves a 1000-pose loop to the known answer", "[hots][sparse_lm]") {
  const auto truth = circle(1000, 100.0);
  const auto start = drifted(truth, 4, 0.5, 2.0 * kDeg);
  PoseGraph g = loop_graph(truth, start, 0.0, 0.0, 1, 50);
  const SparseLmResult r = solve_pose_graph(g);
  INFO(to_string(r.status) << ": " << r.reason << ", iterations " << r.iterations << ", cost "
                           << r.initial_cost << " -> " << r.cost);
  REQUIRE(r.ok());
  CHECK(r.unknowns == 6 * 999);
  CHECK(worst_translation(start, truth) > 1.0);
  CHECK(worst_translation(g.variables, truth) < 1e-6);
  double worst_rot = 0;
  for (std::size_t k = 0; k < truth.size(); ++k)
    worst_rot = std::max(worst_rot, ulc::pose_error(truth[k], g.variables[k]).rotation_deg);
  CHECK(worst_rot < 1e-6);
}

TEST_CASE("sparse LM agrees with a dense Gauss-Newton on a small noisy graph",
          "[hots][sparse_lm]") {
  const auto truth = circle(12, 10.0);
  const auto start = drifted(truth, 7, 0.3, 3.0 * kDeg);
  PoseGraph g = loop_graph(truth, start, 0.02, 0.5 * kDeg, 9, 3);
  // An extrinsic-like variable tied to two pairs of poses.
  const Isometry3d C = random_pose(*std::make_unique<std::mt19937_64>(5), 0.3, 1.0);
  const std::size_t c = g.add_variable(C * ulc::se3_exp(Vec6d::Constant(0.02)));
  for (std::size_t k : {1u, 4u, 8u}) {
    PoseFactor f;
    f.from = k;
    f.to = (k + 1) % truth.size();
    f.from_offset = truth[k].inverse() * truth[f.to] * C.inverse();
    f.measured_var = c;
    f.sqrt_information = isotropic_sqrt_information(0.05, 0.01);
    f.huber = k == 8 ? 0.5 : 0.0;  // one robust factor
    g.add_factor(f);
  }
  PoseGraph dense = g;
  SparseLmOptions options;
  options.step_tolerance = 1e-12;
  options.cost_tolerance = 0.0;
  const SparseLmResult r = solve_pose_graph(g, options);
  REQUIRE((r.ok() || r.status == SparseLmStatus::not_converged));
  // Dense Gauss-Newton with Jacobians from central differences of the whitened residuals
  // (IRLS weights for the Huber factor), nothing shared with the sparse assembly.
  const std::size_t n = dense.variables.size();
  const auto dim = static_cast<Eigen::Index>(6 * (n - 1));
  for (int it = 0; it < 30; ++it) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(dim, dim);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(dim);
    for (const PoseFactor& f : dense.factors) {
      const Vec6d e = f.sqrt_information * linearize_factor(f, dense.variables, false).residual;
      const double w = huber_weight(e.norm(), f.huber);
      Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, dim);
      for (std::size_t v = 1; v < n; ++v) {
        for (int i = 0; i < 6; ++i) {
          Vec6d d = Vec6d::Zero();
          d[i] = 1e-6;
          auto plus = dense.variables, minus = dense.variables;
          plus[v] = ulc::se3_exp(d) * plus[v];
          minus[v] = ulc::se3_exp(Vec6d(-d)) * minus[v];
          J.col(static_cast<Eigen::Index>(6 * (v - 1)) + i) =
              f.sqrt_information *
              (linearize_factor(f, plus, false).residual -
               linearize_factor(f, minus, false).residual) /
              2e-6;
        }
      }
      H += w * J.transpose() * J;
      b += w * J.transpose() * e;
    }
    const Eigen::VectorXd step = H.ldlt().solve(-b);
    for (std::size_t v = 1; v < n; ++v)
      dense.variables[v] =
          ulc::se3_exp(Vec6d(step.segment<6>(static_cast<Eigen::Index>(6 * (v - 1))))) *
          dense.variables[v];
    if (step.cwiseAbs().maxCoeff() < 1e-12) break;
  }
  for (std::size_t v = 0; v < n; ++v) {
    INFO("variable " << v);
    CHECK((g.variables[v].matrix() - dense.variables[v].matrix()).cwiseAbs().maxCoeff() < 1e-7);
  }
  CHECK(g.cost() == Approx(dense.cost()).epsilon(1e-9));
}

TEST_CASE("sparse LM on a noisy loop ends closer to the truth than it starts",
          "[hots][sparse_lm]") {
  const auto truth = circle(300, 40.0);
  const auto start = drifted(truth, 11, 0.3, 1.0 * kDeg);
  PoseGraph g = loop_graph(truth, start, 0.01, 0.1 * kDeg, 12, 10);
  const SparseLmResult r = solve_pose_graph(g);
  REQUIRE(r.ok());
  CHECK(r.cost < r.initial_cost);
  const double before = rms_translation(start, truth);
  const double after = rms_translation(g.variables, truth);
  INFO("rms translation " << before << " -> " << after);
  CHECK(after < 0.2 * before);
}

TEST_CASE("sparse LM gives the same bits on 1 and 2 threads", "[hots][sparse_lm]") {
  const auto truth = circle(400, 40.0);
  const auto start = drifted(truth, 21, 0.3, 1.0 * kDeg);
  PoseGraph one = loop_graph(truth, start, 0.01, 0.1 * kDeg, 22, 10);
  PoseGraph two = one;
  SparseLmOptions options;
  options.grain = 16;
  SparseLmResult r1, r2;
  tbb::task_arena(1).execute([&] { r1 = solve_pose_graph(one, options); });
  tbb::task_arena(2).execute([&] { r2 = solve_pose_graph(two, options); });
  REQUIRE(r1.ok());
  CHECK(r1.iterations == r2.iterations);
  CHECK(r1.cost == r2.cost);
  for (std::size_t k = 0; k < one.variables.size(); ++k)
    CHECK(one.variables[k].matrix() == two.variables[k].matrix());
}

TEST_CASE("sparse LM rejects a malformed graph", "[hots][sparse_lm]") {
  PoseGraph g;
  g.add_variable(Isometry3d::Identity(), true);
  g.add_variable(Isometry3d::Identity());
  PoseFactor f;
  f.from = 0;
  f.to = 5;
  g.add_factor(f);
  CHECK(solve_pose_graph(g).status == SparseLmStatus::invalid_input);
  g.factors[0].to = 0;
  CHECK(solve_pose_graph(g).status == SparseLmStatus::invalid_input);
}

TEST_CASE("the marginal covariance of a variable matches the dense inverse", "[hots][sparse_lm]") {
  const auto truth = circle(8, 5.0);
  PoseGraph g = loop_graph(truth, truth, 0.0, 0.0, 1, 2);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(42, 42);
  for (const PoseFactor& f : g.factors) {
    const FactorLinearization lin = linearize_factor(f, g.variables);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, 42);
    if (f.from > 0) J.block<6, 6>(0, static_cast<Eigen::Index>(6 * (f.from - 1))) = lin.J_from;
    if (f.to > 0) J.block<6, 6>(0, static_cast<Eigen::Index>(6 * (f.to - 1))) = lin.J_to;
    J = f.sqrt_information * J;
    H += J.transpose() * J;
  }
  const Eigen::MatrixXd cov = H.inverse();
  const Mat6d block = marginal_covariance(g, 5);
  CHECK((block - cov.block<6, 6>(24, 24)).norm() < 1e-9 * cov.norm());
}
