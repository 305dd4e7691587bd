// ulc/core/observability.hpp on constructed point-to-plane information: scenes whose geometry
// leaves known directions free (a tunnel, a lone ground plane, a corridor turned by an
// extrinsic) and one that pins all six.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "ulc/core/lie.hpp"
#include "ulc/core/observability.hpp"

using ulc::Isometry3d;
using ulc::Mat6d;
using ulc::Vec3d;
using ulc::Vec6d;

namespace {

/// A plane patch: points on a grid spanned by u and v around `origin`, with normal n.
struct Patch {
  Vec3d origin, u, v, n;
};

struct Information {
  Mat6d H = Mat6d::Zero();
  Vec3d centre = Vec3d::Zero();
  ulc::Mat3d covariance = ulc::Mat3d::Zero();
};

/// sum J J^T with J = [n; y x n] (a left perturbation, point_to_plane.hpp), the points'
/// centroid and covariance, as the acceptance and the whole-sequence step sum them.
Information information(const std::vector<Patch>& patches) {
  Information out;
  std::vector<Vec3d> points;
  for (const Patch& p : patches)
    for (int i = -10; i <= 10; ++i)
      for (int j = -10; j <= 10; ++j) {
        const Vec3d y = p.origin + 0.5 * i * p.u + 0.5 * j * p.v;
        Vec6d J;
        J << p.n, y.cross(p.n);
        out.H += J * J.transpose();
        points.push_back(y);
      }
  for (const Vec3d& y : points) out.centre += y;
  out.centre /= static_cast<double>(points.size());
  for (const Vec3d& y : points) out.covariance += (y - out.centre) * (y - out.centre).transpose();
  out.covariance /= static_cast<double>(points.size());
  return out;
}

const Vec3d X = Vec3d::UnitX(), Y = Vec3d::UnitY(), Z = Vec3d::UnitZ();

/// A tunnel along x: floor, ceiling and two walls, all parallel to x.
std::vector<Patch> tunnel() {
  return {{Vec3d(0, 0, -2), X, Y, Z},
          {Vec3d(0, 0, 4), X, Y, -Z},
          {Vec3d(0, 5, 1), X, Z, -Y},
          {Vec3d(0, -5, 1), X, Z, Y}};
}

ulc::Observability judge(const std::vector<Patch>& patches) {
  const Information info = information(patches);
  return ulc::observability(info.H, info.centre, info.covariance);
}

}  // namespace

TEST_CASE("observability: a room of planes facing every way pins all six directions",
          "[core][observability]") {
  std::vector<Patch> room = tunnel();
  room.push_back({Vec3d(12, 0, 1), Y, Z, -X});
  room.push_back({Vec3d(-12, 0, 1), Y, Z, X});
  const ulc::Observability o = judge(room);
  INFO("weakest share " << o.weakest_share);
  CHECK(o.weakest_share > 0.05);
  CHECK_FALSE(o.degenerate());
}

TEST_CASE("observability: in a tunnel, translation along its axis is free",
          "[core][observability]") {
  const ulc::Observability o = judge(tunnel());
  REQUIRE(o.unobservable.size() == 1);
  const ulc::UnobservableDirection& d = o.unobservable[0];
  CHECK(d.share < 1e-9);
  CHECK(d.vector.norm() == Approx(1.0));
  CHECK(d.vector[0] == Approx(1.0).margin(1e-6));  // +x: the sign makes the largest positive
  CHECK(d.words ==
        "translation along x of the base frame is unobservable: the scene is the same along it");
}

TEST_CASE("observability: a lone ground plane leaves two translations and the yaw free",
          "[core][observability]") {
  const ulc::Observability o = judge({{Vec3d(3, 1, -2), X, Y, Z}});
  REQUIRE(o.unobservable.size() == 3);
  // The free subspace is spanned by translation along x and y and the turn about z.
  Mat6d P = Mat6d::Zero();
  for (const auto& d : o.unobservable) P += d.vector * d.vector.transpose();
  CHECK(P(0, 0) == Approx(1.0).margin(1e-6));
  CHECK(P(1, 1) == Approx(1.0).margin(1e-6));
  CHECK(P(5, 5) == Approx(1.0).margin(1e-6));
  CHECK(P(2, 2) == Approx(0.0).margin(1e-6));
  int rotations = 0;
  for (const auto& d : o.unobservable)
    rotations += d.words.rfind("rotation about z of the base frame", 0) == 0;
  CHECK(rotations == 1);
}

TEST_CASE("observability: seen from the target's side, the free direction turns with C",
          "[core][observability]") {
  // The tunnel measured in the target's frame, whose x axis is the base's y (yaw 90 deg).
  const Information b_side = information(tunnel());
  Isometry3d C = Isometry3d::Identity();
  C.linear() = ulc::so3_exp(Vec3d(0, 0, M_PI / 2));
  C.translation() = Vec3d(0.4, -1.2, 0.3);
  const Mat6d H_a = ulc::information_in_base(b_side.H, C);
  const ulc::Mat3d R = C.linear();
  const ulc::Observability o =
      ulc::observability(H_a, C * b_side.centre, ulc::Mat3d(R * b_side.covariance * R.transpose()));
  REQUIRE(o.unobservable.size() == 1);
  CHECK(std::abs(o.unobservable[0].vector[1]) == Approx(1.0).margin(1e-6));
  CHECK(o.unobservable[0].words.rfind("translation along y of the base frame", 0) == 0);
  // The shares do not depend on the side.
  const ulc::Observability same = ulc::observability(b_side.H, b_side.centre, b_side.covariance);
  CHECK(o.weakest_share == Approx(same.weakest_share).margin(1e-12));
}

TEST_CASE("observability: a corridor along a diagonal names both axes", "[core][observability]") {
  const Vec3d along = Vec3d(1, 1, 0).normalized(), across = Vec3d(-1, 1, 0).normalized();
  const ulc::Observability o = judge({{Vec3d(0, 0, -2), along, across, Z},
                                      {Vec3d(0, 0, 4), along, across, -Z},
                                      {5 * across, along, Z, -across},
                                      {-5 * across, along, Z, across}});
  REQUIRE(o.unobservable.size() == 1);
  CHECK(o.unobservable[0].words ==
        "translation along x and y (0.71, 0.71, 0.00) of the base frame is unobservable: the "
        "scene is the same along it");
}

TEST_CASE("observability: no information leaves every direction free", "[core][observability]") {
  const ulc::Mat3d unit = ulc::Mat3d::Identity();
  const ulc::Observability o = ulc::observability(Mat6d::Zero(), Vec3d::Zero(), unit);
  CHECK(o.unobservable.size() == 6);
  CHECK(o.weakest_share == 0.0);
  Mat6d nan = Mat6d::Identity();
  nan(2, 2) = std::nan("");
  CHECK(ulc::observability(nan, Vec3d::Zero(), unit).unobservable.size() == 6);
}

TEST_CASE("observability: a narrow, deep view's roll about its beam is judged by its own lever",
          "[core][observability]") {
  // What a Tele-15 sees 60-100 m ahead: a wall facing it and two tilted facades, all within
  // a few metres of its beam (x). A turn about x moves these points by metres, not by the
  // tens of metres of the view's depth: measured by its own lever, the roll is pinned, and
  // the translation along the road too.
  const Vec3d tilt_l = Vec3d(-1, -1, 0).normalized(), tilt_r = Vec3d(-1, 1, 0).normalized();
  const ulc::Observability o =
      judge({{Vec3d(100, 0, 0), Y * 0.3, Z * 0.3, -X},
             {Vec3d(60, 4, 0), Vec3d(1, -1, 0).normalized(), Z * 0.3, tilt_l},
             {Vec3d(60, -4, 0), Vec3d(1, 1, 0).normalized(), Z * 0.3, tilt_r},
             {Vec3d(80, 0, -2), X, Y * 0.3, Z}});
  INFO("weakest share " << o.weakest_share);
  CHECK_FALSE(o.degenerate());
}
