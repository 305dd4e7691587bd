// The whole-sequence step of HOTS (sequence_extrinsic.hpp): its 7-parameter Jacobian against
// finite differences, the extrinsic recovered from the base's true trajectory on a simulated
// 64-32 drive (the same for 1 and 2 threads), and the clock offset's trust check.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "hots/hots.hpp"
#include "hots/sequence_extrinsic.hpp"
#include "hots_drive.hpp"
#include "hots_test_util.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/mahalanobis.hpp"
#include "ulc/core/pose_error.hpp"

namespace {

using hots_test::kDeg;
using ulc::Isometry3d;
using ulc::Vec3d;
using ulc::Vec6d;

struct Prepared {
  std::vector<std::vector<ulc::Vec3<float>>> fa, fb;
  hots::HierarchyResult<float> ha;
};

/// The base's frames and hierarchy from its true poses, the target's frames deskewed by truth.
const Prepared& prepared() {
  static const Prepared p = [] {
    const auto& d = hots_drive::drive();
    const auto& a = d.data.lidars[0];
    const auto& b = d.data.lidars[1];
    Prepared out;
    out.fa = hots::hots_detail::prepare_frames<float>(a.frames, a.timestamps, d.truth_a, 0.1);
    out.fb = hots::hots_detail::prepare_frames<float>(b.frames, b.timestamps, d.truth_b, 0.1);
    out.ha = hots::build_hierarchy(out.fa, d.truth_a, hots::HierarchyOptions{});
    return out;
  }();
  return p;
}

/// What the whole-drive cases read: the drive, its two LiDARs, their prepared frames, the truth.
struct DriveCase {
  const hots_drive::Drive& d = hots_drive::drive();
  const ulc::sim::LidarRecording& a = d.data.lidars[0];
  const ulc::sim::LidarRecording& b = d.data.lidars[1];
  const Prepared& p = prepared();
  const Isometry3d C = d.data.pairs[0].T_base_target;

  /// The step on the base's true trajectory, from C0 and a start offset of 0.
  hots::SequenceExtrinsicResult solve(const std::vector<double>& times_b, const Isometry3d& C0,
                                      const hots::SequenceExtrinsicOptions& o = {}) const {
    return hots::sequence_extrinsic(p.ha, p.fa, a.timestamps, d.truth_a, p.fb, times_b, C0, 0.0, o);
  }
};

}  // namespace

TEST_CASE("the joint residual's Jacobian matches finite differences in C and dt",
          "[hots][sequence]") {
  std::mt19937_64 rng(11);
  const std::vector<double> times{0.0, 0.1, 0.2, 0.3};
  std::vector<Isometry3d> poses{hots_test::random_pose(rng, 0.3, 2.0)};
  for (int k = 1; k < 4; ++k)
    poses.push_back(poses.back() * hots_test::random_pose(rng, 5 * kDeg, 1.0));
  const Isometry3d anchor_inverse = hots_test::random_pose(rng, 0.5, 3.0);
  const Isometry3d C = hots_test::random_pose(rng, 0.5, 1.0);
  const Vec3d x(4.0, -2.0, 1.5);
  ulc::PlaneMatch plane;
  plane.normal = Vec3d(0.3, -0.5, 0.8).normalized();
  plane.point = Vec3d(1.0, 2.0, -1.0);
  const double t = 0.137, h = 1e-4;

  const auto [post, dpost] = hots::sequence_detail::placement(times, poses, anchor_inverse, t, h);
  hots::sequence_detail::Vec7 J, unused;
  const double r = hots::sequence_detail::joint_residual(x, C, post, dpost, plane, J);
  const double eps = 1e-6;
  for (int i = 0; i < 6; ++i) {
    ulc::Vec6d xi = ulc::Vec6d::Zero();
    xi[i] = eps;
    const double rp =
        hots::sequence_detail::joint_residual(x, ulc::se3_exp(xi) * C, post, dpost, plane, unused);
    xi[i] = -eps;
    const double rm =
        hots::sequence_detail::joint_residual(x, ulc::se3_exp(xi) * C, post, dpost, plane, unused);
    CHECK(J[i] == Approx((rp - rm) / (2 * eps)).margin(1e-6));
  }
  // dt: the residual with the trajectory read at t +- eps.
  auto at = [&](double tt) {
    const auto pd = hots::sequence_detail::placement(times, poses, anchor_inverse, tt, h);
    return hots::sequence_detail::joint_residual(x, C, pd.first, pd.second, plane, unused);
  };
  CHECK(J[6] == Approx((at(t + 1e-5) - at(t - 1e-5)) / 2e-5).epsilon(1e-6));
  CHECK(r == Approx(at(t)));
}

TEST_CASE("the whole-sequence step recovers the extrinsic from the base's true trajectory",
          "[hots][sequence]") {
  const DriveCase c;
  const Isometry3d& C_gt = c.C;
  std::mt19937_64 rng(5);
  const Isometry3d C0 = jeep_test::disturbed(C_gt, rng, 0.3 * kDeg, 0.05);
  hots::SequenceExtrinsicOptions o;
  o.estimate_time_offset = false;
  o.frame_stride = 2;  // the test drive is short: more of its frames
  auto run = [&] { return c.solve(c.b.timestamps, C0, o); };
  const hots::SequenceExtrinsicResult r = run();
  INFO(hots::to_string(r.status) << ": " << r.reason);
  REQUIRE(r.ok());
  const auto e0 = ulc::pose_error(C_gt, C0);
  const auto e = ulc::pose_error(C_gt, r.extrinsic);
  INFO("start " << e0.rotation_deg << " deg " << e0.translation_m << " m; result " << e.rotation_deg
                << " deg " << e.translation_m << " m; frames " << r.frames << " points "
                << r.source_points << " rmse " << r.rmse);
  CHECK(e.rotation_deg < 0.02);
  CHECK(e.translation_m < 0.005);
  CHECK(r.time_offset_s == 0.0);
  CHECK_FALSE(r.time_offset_refined);
  CHECK(r.frames > 10);

  tbb::task_arena one(1), two(2);
  const auto r1 = one.execute(run);
  const auto r2 = two.execute(run);
  CHECK(r1.extrinsic.matrix() == r2.extrinsic.matrix());
  CHECK(r1.cost == r2.cost);
}

TEST_CASE("time observability is the share of dt's information C cannot explain",
          "[hots][sequence]") {
  using Mat7 = hots::sequence_detail::Mat7;
  using Vec7 = hots::sequence_detail::Vec7;
  // Rows J of a least-squares problem; H = sum J J^T.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  auto normal_matrix = [&](double along_x) {
    Mat7 H = Mat7::Zero();
    for (int i = 0; i < 200; ++i) {
      Vec7 J;
      for (int k = 0; k < 6; ++k) J[k] = n01(rng);
      J[6] = along_x * J[0] + n01(rng);  // dt's column: part translation x, part its own
      H += J * J.transpose();
    }
    return H;
  };
  const double independent = hots::sequence_detail::time_observability(normal_matrix(0.0));
  const double confounded = hots::sequence_detail::time_observability(normal_matrix(30.0));
  CHECK(independent > 0.9);  // 1 for exactly orthogonal columns
  CHECK(confounded == Approx(1.0 / (1.0 + 900.0)).epsilon(0.3));  // 1 / (1 + a^2)
  Mat7 singular = normal_matrix(0.0);
  singular.row(6).setZero();
  singular.col(6).setZero();
  CHECK(hots::sequence_detail::time_observability(singular) == 0.0);
}

TEST_CASE("the trust check flags a clock offset the synchronisation missed", "[hots][sequence]") {
  const DriveCase c;
  const Isometry3d& C = c.C;
  hots::SequenceExtrinsicOptions o;
  o.estimate_time_offset = false;  // as after a synchronisation that found no offset
  o.frame_stride = 2;
  o.min_frames = 0;  // every second frame, however few
  // b's clock 50 ms behind: t_a = t_b + 0.05, while the step is told 0.
  const double offset = 0.05;
  std::vector<double> late_b = c.b.timestamps;
  for (double& t : late_b) t -= offset;
  auto run = [&](const std::vector<double>& times_b, const hots::SequenceExtrinsicOptions& opt) {
    const auto r = c.solve(times_b, C, opt);
    INFO("joint " << r.joint_time_offset_s * 1e3 << " ms, observability " << r.time_observability
                  << ", halves " << r.half_time_offset_s[0] * 1e3 << ", "
                  << r.half_time_offset_s[1] * 1e3 << " ms: " << r.time_offset_doubt);
    REQUIRE(r.ok());
    CHECK(r.time_offset_checked);
    return r;
  };
  // A 3 s drive does not pin an offset down: the default check says so whatever the clocks.
  const auto missed = run(late_b, o);
  CHECK_FALSE(missed.time_offset_trusted);
  CHECK(missed.time_observability < o.min_time_observability);
  CHECK(missed.time_offset_s == 0.0);  // reported, not adopted
  CHECK(std::abs(missed.joint_time_offset_s - offset) < 0.01);
  CHECK_FALSE(run(c.b.timestamps, o).time_offset_trusted);

  // The other two criteria alone: the missed offset is still caught (the whole drive's
  // registration points 50 ms away), the right clocks pass with halves that agree.
  hots::SequenceExtrinsicOptions lenient = o;
  lenient.min_time_observability = 0.0;
  CHECK_FALSE(run(late_b, lenient).time_offset_trusted);
  const auto right = run(c.b.timestamps, lenient);
  CHECK(right.time_offset_trusted);
  CHECK(std::abs(right.half_time_offset_s[0] - right.half_time_offset_s[1]) <
        o.max_time_disagreement_s);
  CHECK(std::abs(right.joint_time_offset_s) < o.max_time_disagreement_s);
}

TEST_CASE("the whole-sequence step refuses bad input and can be switched off", "[hots][sequence]") {
  const DriveCase c;
  const Isometry3d& C = c.C;
  hots::SequenceExtrinsicOptions off;
  off.enabled = false;
  const auto r0 = c.solve(c.b.timestamps, C, off);
  CHECK(r0.status == hots::SequenceExtrinsicStatus::disabled);
  CHECK(r0.extrinsic.matrix() == C.matrix());
  hots::SequenceExtrinsicOptions bad;
  bad.stages.clear();
  CHECK(c.solve(c.b.timestamps, C, bad).status == hots::SequenceExtrinsicStatus::invalid_input);
  const std::vector<Isometry3d> short_poses(c.d.truth_a.begin(), c.d.truth_a.begin() + 2);
  CHECK(hots::sequence_extrinsic(c.p.ha, c.p.fa, c.a.timestamps, short_poses, c.p.fb,
                                 c.b.timestamps, C, 0.0)
            .status == hots::SequenceExtrinsicStatus::invalid_input);
}

TEST_CASE("a prepared whole-sequence step solved from a second start ends where a fresh step does",
          "[hots][sequence]") {
  // HOTS reruns the step from its own start (refine_steps.hpp) on the prepared submaps and
  // frames of the first solve; the answer must be the one a step of its own gives, to the bit,
  // including the offset's check having run in between (it moves the problem's span and terms).
  const DriveCase c;
  std::mt19937_64 rng(9);
  const Isometry3d first = jeep_test::disturbed(c.C, rng, 0.2 * kDeg, 0.03);
  const Isometry3d second = jeep_test::disturbed(c.C, rng, 0.3 * kDeg, 0.05);
  hots::SequenceExtrinsicOptions o;
  o.estimate_time_offset = false;  // the offset is still checked: the joint solve runs too
  o.frame_stride = 2;
  hots::SequenceStep<float> step(c.p.ha, c.p.fa, c.a.timestamps, c.d.truth_a, c.p.fb,
                                 c.b.timestamps, 0.0, o);
  const hots::SequenceExtrinsicResult r1 = step.solve(first);
  REQUIRE(r1.ok());
  CHECK(r1.time_offset_checked);
  const hots::SequenceExtrinsicResult again = step.solve_extrinsic(second, r1.time_offset_refined);
  const hots::SequenceExtrinsicResult fresh = c.solve(c.b.timestamps, second, o);
  REQUIRE(again.ok());
  REQUIRE(fresh.ok());
  CHECK(again.extrinsic.matrix() == fresh.extrinsic.matrix());
  CHECK(again.time_offset_s == fresh.time_offset_s);
  CHECK_FALSE(again.has_covariance);
  CHECK(ulc::pose_error(c.C, again.extrinsic).translation_m < 0.005);
  // The first solve's statistics are the whole drive's, after the halves' check.
  const hots::SequenceExtrinsicResult fresh_first = c.solve(c.b.timestamps, first, o);
  CHECK(r1.frames == fresh_first.frames);
  CHECK(r1.frames == again.frames);
}

TEST_CASE("a second start on a step that refined the clock offset solves with the offset free",
          "[hots][sequence]") {
  // b's clock 50 ms behind, the step started at 30 ms (as from a synchronisation short of the
  // truth) and free to refine the offset: solve() adopts the joint solve, and a second start
  // solved the same way ends where a fresh step from it does.
  const DriveCase c;
  std::vector<double> late_b = c.b.timestamps;
  for (double& t : late_b) t -= 0.05;
  std::mt19937_64 rng(10);
  const Isometry3d first = jeep_test::disturbed(c.C, rng, 0.2 * kDeg, 0.03);
  const Isometry3d second = jeep_test::disturbed(c.C, rng, 0.3 * kDeg, 0.05);
  hots::SequenceExtrinsicOptions o;
  o.check_time_offset = false;
  o.frame_stride = 2;
  const double dt0 = 0.03;
  hots::SequenceStep<float> step(c.p.ha, c.p.fa, c.a.timestamps, c.d.truth_a, c.p.fb, late_b, dt0,
                                 o);
  const hots::SequenceExtrinsicResult r1 = step.solve(first);
  INFO("joint " << r1.joint_time_offset_s * 1e3 << " ms, sigma " << r1.time_sigma_s * 1e3 << " ms");
  REQUIRE(r1.ok());
  REQUIRE(r1.time_offset_refined);
  const hots::SequenceExtrinsicResult again = step.solve_extrinsic(second, true);
  const hots::SequenceExtrinsicResult fresh = hots::sequence_extrinsic(
      c.p.ha, c.p.fa, c.a.timestamps, c.d.truth_a, c.p.fb, late_b, second, dt0, o);
  REQUIRE(again.ok());
  REQUIRE(fresh.time_offset_refined);
  CHECK(again.extrinsic.matrix() == fresh.extrinsic.matrix());
  CHECK(again.time_offset_s == fresh.time_offset_s);
  CHECK(std::abs(again.time_offset_s - 0.05) < 0.01);
  // Held at the step's start offset instead, the same start ends elsewhere: the offset's 20 ms
  // error shows as a move along the drive.
  const hots::SequenceExtrinsicResult held = step.solve_extrinsic(second, false);
  REQUIRE(held.ok());
  CHECK(held.time_offset_s == dt0);
  CHECK(ulc::pose_error(again.extrinsic, held.extrinsic).translation_m > 0.01);
  CHECK(ulc::pose_error(c.C, again.extrinsic).translation_m <
        ulc::pose_error(c.C, held.extrinsic).translation_m);
}

TEST_CASE(
    "C's sensitivity to the clock offset matches finite differences and widens C's covariance",
    "[hots][sequence]") {
  // b's clock 50 ms behind, the step started at 30 ms and free to refine it, the halves' check
  // on: dC/ddt = -H_CC^-1 H_Ct at the answer against C re-solved at dt +- 2 ms, and the
  // covariance carrying the offset's error (half the halves' disagreement times dC/ddt).
  const DriveCase c;
  std::vector<double> late_b = c.b.timestamps;
  for (double& t : late_b) t -= 0.05;
  hots::SequenceExtrinsicOptions o;
  o.frame_stride = 2;
  o.min_frames = 0;
  o.min_time_observability = 0.0;  // the halves run however short the drive
  const hots::SequenceExtrinsicResult r = hots::sequence_extrinsic(
      c.p.ha, c.p.fa, c.a.timestamps, c.d.truth_a, c.p.fb, late_b, c.C, 0.03, o);
  REQUIRE(r.ok());
  REQUIRE(r.time_offset_refined);
  REQUIRE(r.time_offset_checked);
  REQUIRE(r.has_covariance);

  hots::SequenceExtrinsicOptions held = o;
  held.estimate_time_offset = false;
  held.check_time_offset = false;
  const double h = 0.002;
  auto at = [&](double dt) {
    const auto s = hots::sequence_extrinsic(c.p.ha, c.p.fa, c.a.timestamps, c.d.truth_a, c.p.fb,
                                            late_b, r.extrinsic, dt, held);
    REQUIRE(s.ok());
    return s.extrinsic;
  };
  const Vec6d numeric =
      ulc::se3_log(Isometry3d(at(r.time_offset_s + h) * at(r.time_offset_s - h).inverse())) /
      (2.0 * h);
  const Vec6d analytic = r.offset_sensitivity;
  INFO("analytic " << analytic.transpose() << "\nnumeric  " << numeric.transpose());
  CHECK(analytic.head<3>().norm() > 1.0);  // metres per second: about the drive's speed
  CHECK((analytic - numeric).head<3>().norm() < 0.2 * numeric.head<3>().norm());
  CHECK(analytic.head<3>().dot(numeric.head<3>()) >
        0.95 * analytic.head<3>().norm() * numeric.head<3>().norm());

  // The covariance holds the offset's term: its 1-sigma sample lies within 1 sigma.
  const double spread = 0.5 * (r.half_time_offset_s[0] - r.half_time_offset_s[1]);
  REQUIRE(spread != 0.0);
  const Vec6d moved = r.offset_sensitivity * spread;
  const auto d2 = ulc::mahalanobis_sq(moved, r.covariance_6x6);
  REQUIRE(d2);
  CHECK(*d2 <= 1.0 + 1e-9);
}
