// Primitives against hand-computed intersections, and the BVH against brute force.
#include <catch2/catch.hpp>
#include <cmath>

#include "ulc/sim/random.hpp"
#include "ulc/sim/scene.hpp"
#include "ulc/sim/world.hpp"

using namespace ulc::sim;
using ulc::Mat3d;
using ulc::Vec3d;

namespace {

Ray make_ray(const Vec3d& o, const Vec3d& d, std::uint64_t key = 1) {
  Ray r;
  r.origin = o;
  r.dir = d.normalized();
  r.key = key;
  return r;
}

}  // namespace

TEST_CASE("oriented box: entry face, distance and normal, also rotated", "[sim][primitives]") {
  OrientedBox box{Vec3d(10, 0, 0), Mat3d::Identity(), Vec3d(1, 2, 3), 0.5f};
  SurfaceHit hit;
  REQUIRE(box.intersect(make_ray(Vec3d::Zero(), Vec3d::UnitX()), kInfinity, hit));
  CHECK(hit.t == Approx(9.0));
  CHECK(hit.normal.isApprox(-Vec3d::UnitX()));
  CHECK_FALSE(box.intersect(make_ray(Vec3d(0, 2.5, 0), Vec3d::UnitX()), kInfinity, hit));
  CHECK_FALSE(box.intersect(make_ray(Vec3d::Zero(), Vec3d::UnitX()), 8.9, hit));  // beyond t_max
  // Rotated 45 degrees about z: the corner at distance sqrt(2) from the centre faces the ray.
  const Mat3d R = Eigen::AngleAxisd(M_PI / 4, Vec3d::UnitZ()).toRotationMatrix();
  OrientedBox rotated{Vec3d(10, 0, 0), R, Vec3d(1, 1, 1), 0.5f};
  REQUIRE(rotated.intersect(make_ray(Vec3d(0, 0.2, 0), Vec3d::UnitX()), kInfinity, hit));
  CHECK(hit.t == Approx(10.0 - std::sqrt(2.0) + 0.2).epsilon(1e-12));
  // A ray starting inside reports the exit face.
  REQUIRE(box.intersect(make_ray(Vec3d(10, 0, 0), Vec3d::UnitZ()), kInfinity, hit));
  CHECK(hit.t == Approx(3.0));
  CHECK(hit.normal.isApprox(Vec3d::UnitZ()));
}

TEST_CASE("vertical cylinder: side and cap hits", "[sim][primitives]") {
  VerticalCylinder c{5, 0, 0, 4, 0.5, 0.5f};
  SurfaceHit hit;
  REQUIRE(c.intersect(make_ray(Vec3d(0, 0, 1), Vec3d::UnitX()), kInfinity, hit));
  CHECK(hit.t == Approx(4.5));
  CHECK(hit.normal.isApprox(-Vec3d::UnitX()));
  REQUIRE(c.intersect(make_ray(Vec3d(5.1, 0.1, 10), -Vec3d::UnitZ()), kInfinity, hit));
  CHECK(hit.t == Approx(6.0));
  CHECK(hit.normal.isApprox(Vec3d::UnitZ()));
  CHECK_FALSE(c.intersect(make_ray(Vec3d(0, 0, 5), Vec3d::UnitX()), kInfinity, hit));  // above
  CHECK_FALSE(c.intersect(make_ray(Vec3d(0, 0.6, 1), Vec3d::UnitX()), kInfinity, hit));
}

TEST_CASE("triangle: inside, outside and back side", "[sim][primitives]") {
  const Triangle t = Triangle::from_vertices(Vec3d(0, 0, 0), Vec3d(4, 0, 0), Vec3d(0, 4, 0), 0.3f);
  SurfaceHit hit;
  REQUIRE(t.intersect(make_ray(Vec3d(1, 1, 5), -Vec3d::UnitZ()), kInfinity, hit));
  CHECK(hit.t == Approx(5.0));
  CHECK(std::abs(hit.normal.z()) == Approx(1.0));
  REQUIRE(t.intersect(make_ray(Vec3d(1, 1, -2), Vec3d::UnitZ()), kInfinity, hit));
  CHECK(hit.t == Approx(2.0));
  CHECK_FALSE(t.intersect(make_ray(Vec3d(3, 3, 5), -Vec3d::UnitZ()), kInfinity, hit));
}

TEST_CASE("porous canopy: stop depth is exponential with the set density", "[sim][primitives]") {
  // A long thin ellipsoid traversed along its axis: 20 m of foliage at density 0.25 / m.
  PorousEllipsoid e{Vec3d(0, 0, 0), Vec3d(10, 1, 1), 0.25, 0.4f};
  double sum = 0.0;
  int stopped = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    SurfaceHit hit;
    if (e.intersect(make_ray(Vec3d(-20, 0, 0), Vec3d::UnitX(), static_cast<std::uint64_t>(i)),
                    kInfinity, 7, hit)) {
      ++stopped;
      sum += hit.t - 10.0;
    }
  }
  // P(stop within 20 m) = 1 - exp(-5); the same ray key always stops at the same depth.
  CHECK(stopped / double(n) == Approx(1.0 - std::exp(-5.0)).margin(0.01));
  CHECK(sum / stopped < 4.0);  // truncated exponential mean (~3.87 m) below 1 / density
  CHECK(sum / stopped > 3.6);
  SurfaceHit a, b;
  REQUIRE(e.intersect(make_ray(Vec3d(-20, 0, 0), Vec3d::UnitX(), 42), kInfinity, 7, a));
  REQUIRE(e.intersect(make_ray(Vec3d(-20, 0, 0), Vec3d::UnitX(), 42), kInfinity, 7, b));
  CHECK(a.t == b.t);
}

TEST_CASE("BVH closest hit equals brute force on a random box field", "[sim][bvh]") {
  Scene scene;
  CounterRng rng(5);
  for (int i = 0; i < 3000; ++i) {
    const Vec3d c(rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-5, 5));
    const Mat3d R = Eigen::AngleAxisd(rng.uniform(0, 6.3),
                                      Vec3d(rng.uniform(-1, 1), rng.uniform(-1, 1), 1).normalized())
                        .toRotationMatrix();
    switch (i % 4) {
      case 0:
        scene.add(OrientedBox{
            c, R, Vec3d(rng.uniform(0.1, 2), rng.uniform(0.1, 2), rng.uniform(0.1, 2)), 0.5f});
        break;
      case 1:
        scene.add(VerticalCylinder{c.x(), c.y(), c.z(), c.z() + rng.uniform(0.5, 4),
                                   rng.uniform(0.05, 1), 0.5f});
        break;
      case 2:
        scene.add(Triangle::from_vertices(c, c + R.col(0) * 3, c + R.col(1) * 3, 0.5f));
        break;
      default:
        scene.add(PorousEllipsoid{
            c, Vec3d(rng.uniform(0.5, 3), rng.uniform(0.5, 3), rng.uniform(0.5, 3)), 0.8, 0.4f});
    }
  }
  scene.build();
  int hits = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3d o(rng.uniform(-60, 60), rng.uniform(-60, 60), rng.uniform(-8, 8));
    const Vec3d d(rng.normal(), rng.normal(), 0.3 * rng.normal());
    Ray ray = make_ray(o, d, static_cast<std::uint64_t>(i));
    ray.t_max = (i % 3 == 0) ? 30.0 : kInfinity;
    SurfaceHit a, b;
    const bool ha = scene.intersect(ray, a);
    const bool hb = scene.intersect_brute_force(ray, b);
    REQUIRE(ha == hb);
    if (ha) {
      ++hits;
      REQUIRE(a.t == b.t);
      REQUIRE(a.normal == b.normal);
    }
  }
  CHECK(hits > 1000);
}

TEST_CASE("BVH closest hit equals brute force in the town, from street level", "[sim][bvh]") {
  const World world = build_world(SceneKind::town, 3, 400.0);
  REQUIRE(world.scene.size() > 10000);
  REQUIRE(world.scene.ground().cell_count() > 10000);
  CounterRng rng(9);
  int hits = 0;
  for (int i = 0; i < 300; ++i) {
    const auto p = world.route.at(rng.uniform(0, world.route.length()));
    const Vec3d o(p.position.x(), p.position.y(),
                  world.ground.height(p.position.x(), p.position.y()) + 1.8);
    const double az = rng.uniform(0, 6.3), el = rng.uniform(-0.5, 0.3);
    Ray ray =
        make_ray(o, Vec3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)),
                 static_cast<std::uint64_t>(i));
    ray.t_max = 150.0;
    SurfaceHit a, b;
    const bool ha = world.scene.intersect(ray, a);
    REQUIRE(ha == world.scene.intersect_brute_force(ray, b));
    if (ha) {
      ++hits;
      REQUIRE(a.t == Approx(b.t).epsilon(1e-12));  // ground: plane form vs triangles
    }
  }
  CHECK(hits > 250);  // rays at street level nearly always hit something within 150 m
}

TEST_CASE("ground grid walk equals brute force over its triangles", "[sim][ground]") {
  GroundMeshSpec spec;
  spec.x0 = -40;
  spec.y0 = -30;
  spec.x1 = 60;
  spec.y1 = 50;
  spec.spacing = 2.5;
  spec.roughness = 0.05;
  spec.key = 4;
  const GroundRelief relief = GroundRelief::random(8, 3.0);  // exaggerated relief
  const GroundGrid grid(relief, spec, [](double x, double) { return x > 0 ? 0.1f : 0.3f; });
  const std::vector<Triangle> tris = grid.triangles();
  REQUIRE(tris.size() == 2 * 40 * 32);
  CounterRng rng(3);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    // From above, grazing and from outside the grid; some rays pointing up.
    const Vec3d o(rng.uniform(-70, 90), rng.uniform(-60, 80), rng.uniform(-1, 6));
    const Vec3d d(rng.normal(), rng.normal(),
                  i % 5 == 0 ? 0.3 * rng.normal() : -0.05 - 0.3 * rng.uniform());
    Ray ray = make_ray(o, d);
    SurfaceHit a, b;
    const bool ha = grid.intersect(ray, kInfinity, a);
    double best = kInfinity;
    bool hb = false;
    for (const Triangle& t : tris)
      if (t.intersect(ray, best, b)) {
        best = b.t;
        hb = true;
      }
    REQUIRE(ha == hb);
    if (ha) {
      ++hits;
      REQUIRE(a.t == Approx(b.t).epsilon(1e-12));
      REQUIRE(a.reflectivity == b.reflectivity);
    }
  }
  CHECK(hits > 500);
}
