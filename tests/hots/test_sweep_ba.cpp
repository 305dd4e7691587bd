// Window BA with continuous-time sweeps (sweep_ba.hpp): the variables' gradient against finite
// differences of the cost, and knots recovered from sweeps deskewed with a wrong motion, which a
// rigid frame cannot fit.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "assembled_hessian.hpp"
#include "hots/sweep_ba.hpp"
#include "hots/window_ba.hpp"
#include "hots_test_util.hpp"
#include "ulc/core/pose_error.hpp"

namespace sweep_test {

using namespace hots;
using namespace hots_test;
using Cloud = std::vector<Vec3d>;

/// Sweeps of a spinning sensor between true knots: a point's fraction of the sweep is its
/// azimuth, the sensor moves at constant velocity between the knots, and the points are
/// deskewed with the motion of other ("odometry") knots, as HOTS does.
struct Sweeps {
  std::vector<Isometry3d> truth;     ///< knots, one more than sweeps
  std::vector<Isometry3d> odometry;  ///< disturbed knots: the start and the deskew motions
  std::vector<std::vector<Cloud>> parts;
  std::vector<std::vector<double>> fraction;
  std::vector<Cloud> frames;  ///< each sweep's parts together (for the rigid BA)

  SweepWindow<Cloud> window() const {
    SweepWindow<Cloud> w;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      w.deskew.push_back(odometry[k].inverse() * odometry[k + 1]);
      for (std::size_t j = 0; j < parts[k].size(); ++j) {
        if (parts[k][j].empty()) continue;
        w.clouds.push_back(&parts[k][j]);
        w.sweep.push_back(k);
        w.fraction.push_back(fraction[k][j]);
      }
    }
    w.deskew.push_back(Isometry3d::Identity());  // the end knot has no sweep
    return w;
  }
};

Sweeps make_sweeps(std::size_t parts_per_sweep) {
  constexpr std::size_t kSweeps = 5;
  Sweeps out;
  out.truth = room_path(kSweeps + 1, 0.6);
  std::mt19937_64 rng(21);
  out.odometry = out.truth;
  for (std::size_t k = 1; k < out.odometry.size(); ++k)
    out.odometry[k] = out.odometry[k] * ulc::se3_exp(random_vector6(rng, 0.02, 0.2 * kDeg));
  Room room;
  for (std::size_t k = 0; k < kSweeps; ++k) {
    const Vec6d motion = ulc::se3_log(Isometry3d(out.truth[k].inverse() * out.truth[k + 1]));
    const Vec6d deskew = ulc::se3_log(Isometry3d(out.odometry[k].inverse() * out.odometry[k + 1]));
    std::vector<Cloud> parts(parts_per_sweep);
    std::vector<double> sum(parts_per_sweep, 0.0);
    for (const Vec3d& p : room.sample(out.truth[k].translation(), 25.0, 0.25, 0.01, rng)) {
      const Vec3d q = out.truth[k].inverse() * p;
      const double s = (std::atan2(q.y(), q.x()) + M_PI) / (2.0 * M_PI);
      const Isometry3d at_s = out.truth[k] * ulc::se3_exp(Vec6d(s * motion));
      const Vec3d raw = at_s.inverse() * p;
      const auto j = std::min(static_cast<std::size_t>(s * parts_per_sweep), parts_per_sweep - 1);
      parts[j].push_back(ulc::se3_exp(Vec6d(s * deskew)) * raw);
      sum[j] += s;
    }
    Cloud frame;
    std::vector<double> fraction;
    for (std::size_t j = 0; j < parts_per_sweep; ++j) {
      fraction.push_back(parts[j].empty() ? 0.0 : sum[j] / static_cast<double>(parts[j].size()));
      frame.insert(frame.end(), parts[j].begin(), parts[j].end());
    }
    out.parts.push_back(std::move(parts));
    out.fraction.push_back(std::move(fraction));
    out.frames.push_back(std::move(frame));
  }
  return out;
}

/// Eight parts per sweep; `fine` has 32.
const Sweeps& sweeps(bool fine = false) {
  static const Sweeps coarse_sweeps = make_sweeps(8), fine_sweeps = make_sweeps(32);
  return fine ? fine_sweeps : coarse_sweeps;
}

ulc::PoseError worst_knot_error(const std::vector<Isometry3d>& truth,
                                const std::vector<Isometry3d>& est, std::size_t count) {
  ulc::PoseError worst;
  for (std::size_t i = 1; i < count; ++i) {
    const auto e = ulc::pose_error(Isometry3d(truth[0].inverse() * truth[i]),
                                   Isometry3d(est[0].inverse() * est[i]));
    worst.rotation_deg = std::max(worst.rotation_deg, e.rotation_deg);
    worst.translation_m = std::max(worst.translation_m, e.translation_m);
  }
  return worst;
}

}  // namespace sweep_test

TEST_CASE("sweep BA: the knots' gradient is the cost's derivative", "[hots][sweep_ba]") {
  using namespace sweep_test;
  const Sweeps& s = sweeps();
  const SweepWindow<Cloud> w = s.window();
  std::vector<Isometry3d> x = s.odometry;  // window frame: knot 0 at the origin
  for (auto& T : x) T = s.odometry[0].inverse() * T;
  WindowBaOptions options;
  const auto planes = extract_planes(w.clouds, sweep_ba_detail::entry_poses(w, x), options.planes);
  REQUIRE(planes.size() > 50);
  const auto sums = sweep_ba_detail::evaluate(planes, w, x, options);
  auto cost_at = [&](std::size_t var, int axis, double h) {
    std::vector<Isometry3d> y = x;
    Vec6d d = Vec6d::Zero();
    d(axis) = h;
    y[var] = ulc::se3_exp(d) * y[var];
    return window_ba_detail::cost(planes, sweep_ba_detail::entry_poses(w, y), options);
  };
  for (std::size_t var = 0; var < x.size(); ++var) {
    for (int axis = 0; axis < 6; ++axis) {
      const double h = 1e-5;
      const double numeric = (cost_at(var, axis, h) - cost_at(var, axis, -h)) / (2.0 * h);
      const double analytic = sums.g(static_cast<Eigen::Index>(6 * var + axis));
      INFO("knot " << var << " axis " << axis);
      CHECK(analytic == Approx(numeric).epsilon(1e-4).margin(1e-6 * sums.g.norm()));
    }
  }
}

TEST_CASE("sweep BA: the knots' Hessian is the planes' Hessians through the entries' Jacobians",
          "[hots][sweep_ba]") {
  // The reference: each plane's dense Hessian over its entries (evaluate_plane, itself checked
  // against central differences in test_point_cluster) mapped by J_e into the knots, term by
  // term. evaluate() sums the same from factors and per-entry blocks.
  using namespace sweep_test;
  const Sweeps& s = sweeps();
  const SweepWindow<Cloud> w = s.window();
  std::vector<Isometry3d> x = s.odometry;
  for (auto& T : x) T = s.odometry[0].inverse() * T;
  WindowBaOptions options;
  const auto entries = sweep_ba_detail::entry_poses(w, x);
  const auto planes = extract_planes(w.clouds, entries, options.planes);
  REQUIRE(planes.size() > 50);
  const auto n = static_cast<Eigen::Index>(6 * x.size());
  std::vector<Eigen::MatrixXd> to_knots;  // per entry: 6 x 6V, J_e placed at its knots
  for (std::size_t e = 0; e < entries.size(); ++e) {
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, n);
    const auto Je = sweep_ba_detail::entry_jacobian(w, x, e);
    const auto at = static_cast<Eigen::Index>(6 * w.sweep[e]);
    const Eigen::Index cols = std::min<Eigen::Index>(12, n - at);
    J.middleCols(at, cols) = Je.leftCols(cols);
    to_knots.push_back(J);
  }
  const Eigen::MatrixXd reference =
      hots_test::assembled_hessian(planes, entries, options.evaluation, to_knots);
  const auto sums = sweep_ba_detail::evaluate(planes, w, x, options);
  CHECK((sums.H - reference).norm() <= 1e-9 * reference.norm());
  CHECK(reference.norm() > 0.0);
}

TEST_CASE("sweep BA recovers knots from sweeps deskewed with a wrong motion", "[hots][sweep_ba]") {
  using namespace sweep_test;
  const Sweeps& s = sweeps();
  const auto start = worst_knot_error(s.truth, s.odometry, s.truth.size());
  const SweepBaResult r = sweep_window_ba(s.window(), s.odometry);
  INFO(to_string(r.ba.status) << ": planes " << r.ba.planes << ", cost " << r.ba.initial_cost
                              << " -> " << r.ba.cost);
  REQUIRE(r.ba.ok());
  CHECK(r.ba.poses[0].isApprox(s.odometry[0], 0.0));
  const auto e = worst_knot_error(s.truth, r.ba.poses, s.truth.size() - 1);
  const auto e_end = worst_knot_error(s.truth, r.ba.poses, s.truth.size());
  // The rigid BA on the same points, deskewed with the same wrong motion.
  std::vector<Isometry3d> rigid_start(s.odometry.begin(), s.odometry.end() - 1);
  const WindowBaResult rigid = window_ba(s.frames, rigid_start);
  REQUIRE(rigid.ok());
  const auto er = worst_knot_error(s.truth, rigid.poses, rigid.poses.size());
  INFO("start " << start.translation_m << " m " << start.rotation_deg << " deg; sweeps "
                << e.translation_m << " m " << e.rotation_deg
                << " deg (end knot too: " << e_end.translation_m << " m " << e_end.rotation_deg
                << " deg); rigid " << er.translation_m << " m " << er.rotation_deg << " deg");
  CHECK(start.translation_m > 0.03);
  CHECK(e.translation_m < 0.01);
  CHECK(e.rotation_deg < 0.06);
  CHECK(e_end.translation_m < 0.015);
  CHECK(er.translation_m > 3.0 * e.translation_m);
  // A part's points are placed at its mean time: the error is first order in the part's
  // duration, so four times the parts leave well under half of it.
  const Sweeps& fine = sweeps(true);
  const SweepBaResult rf = sweep_window_ba(fine.window(), fine.odometry);
  REQUIRE(rf.ba.ok());
  const auto ef = worst_knot_error(fine.truth, rf.ba.poses, fine.truth.size() - 1);
  INFO("32 parts: " << ef.translation_m << " m " << ef.rotation_deg << " deg");
  CHECK(ef.translation_m < 0.5 * e.translation_m);
  CHECK(ef.rotation_deg < 0.5 * e.rotation_deg);
  // The noise estimate sees the 1 cm simulated noise: the sweeps are undistorted.
  CHECK(std::sqrt(r.ba.noise_variance) == Approx(0.01).epsilon(0.3));
}

TEST_CASE("sweep BA gives the same bits on 1 and 2 threads", "[hots][sweep_ba]") {
  using namespace sweep_test;
  const Sweeps& s = sweeps();
  WindowBaOptions options;
  options.grain = 8;
  SweepBaResult one, two;
  tbb::task_arena(1).execute([&] { one = sweep_window_ba(s.window(), s.odometry, options); });
  tbb::task_arena(2).execute([&] { two = sweep_window_ba(s.window(), s.odometry, options); });
  REQUIRE(one.ba.ok());
  CHECK(one.ba.cost == two.ba.cost);
  for (std::size_t i = 0; i < one.ba.poses.size(); ++i)
    CHECK(one.ba.poses[i].matrix() == two.ba.poses[i].matrix());
  CHECK(one.ba.hessian == two.ba.hessian);
}

TEST_CASE("sweep BA reports inconsistent input", "[hots][sweep_ba]") {
  using namespace sweep_test;
  const Sweeps& s = sweeps();
  SweepWindow<Cloud> w = s.window();
  w.sweep.back() = 99;  // an entry on a knot that does not exist
  CHECK(sweep_window_ba(w, s.odometry).ba.status == WindowBaStatus::invalid_input);
  CHECK(sweep_window_ba(s.window(), {s.odometry[0]}).ba.status == WindowBaStatus::invalid_input);
}
