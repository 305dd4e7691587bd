#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "terra/descriptor.hpp"
#include "terra/distance.hpp"
#include "terra/kdtree_lookup.hpp"
#include "terra/lattice.hpp"
#include "terra/random_rotation.hpp"
#include "terra/rotate.hpp"
#include "terra_test_util.hpp"

namespace {

template <typename S>
terra::Descriptor<S> hand_made(std::vector<S> r) {
  terra::Descriptor<S> f;
  f.range = std::move(r);
  return f;
}

}  // namespace

TEMPLATE_TEST_CASE("eq:mask and eq:feature_dis on hand-made descriptors", "[distance]", float,
                   double) {
  using S = TestType;
  //                         empty  ok   >d2  F2=d1  ok  F1<d1 =d2  equal
  const auto f1 = hand_made<S>({0, 25, 30, 21, 50, 19, 40, 100});
  const auto f2 = hand_made<S>({25, 26, 36, 20, 52, 25, 45, 100});
  terra::DistanceParams p;  // d1 20, d2 5, alpha 2
  auto v = terra::descriptor_distance(f1, f2, p);
  CHECK(v.mask_count == 4);  // cells 1, 4, 6 (|diff| = d2 is in), 7
  CHECK(v.abs_sum == 8.0);   // 1 + 2 + 5 + 0
  CHECK(v.distance == 8.0 / 16.0);
  p.alpha = 1.0;
  CHECK(terra::descriptor_distance(f1, f2, p).distance == 2.0);
  p.d2 = 4.99;  // cell 6 drops out
  v = terra::descriptor_distance(f1, f2, p);
  CHECK(v.mask_count == 3);
  CHECK(v.distance == 1.0);
  p = terra::DistanceParams();
  p.d1 = 100.0;  // nothing beyond 100 m: no overlap, infinite distance
  v = terra::descriptor_distance(f1, f2, p);
  CHECK(!v.overlap());
  CHECK(v.distance == std::numeric_limits<double>::infinity());
  // Symmetric in its arguments.
  CHECK(terra::descriptor_distance(f2, f1, terra::DistanceParams()).distance == 0.5);
  // Mismatched sizes: no overlap rather than reading out of bounds.
  CHECK(!terra::descriptor_distance(f1, hand_made<S>({1, 2}), terra::DistanceParams()).overlap());
}

TEST_CASE("fused rotated distance equals distance to the rotated descriptor", "[distance]") {
  const terra::Lattice lattice(10000);
  const terra::KdTreeLookup kd(lattice);
  const auto f1 = terra::make_descriptor(lattice, terra_test::scan(ulc::Mat3d::Identity()));
  terra::SplitMix64 rng(8);
  const ulc::Mat3d turn = terra::random_rotation(rng);
  const auto f2 = terra::make_descriptor(lattice, terra_test::scan(turn, ulc::Vec3d(0.2, 0, 0)));
  const terra::DistanceParams p;
  const auto base = terra::base_cells(lattice, f1, p.d1);
  const auto target = terra::target_cells(f2, p.d1);
  CHECK(base.size() == f1.cells_beyond(p.d1));
  std::vector<ulc::Mat3d> rotations = {ulc::Mat3d::Identity(), turn};
  for (int t = 0; t < 6; ++t) rotations.push_back(terra::random_rotation(rng));
  for (const auto& R : rotations) {
    const auto plain = terra::descriptor_distance(f1, terra::rotate(lattice, f2, R), p);
    const auto fused = terra::rotated_distance(base, target, lattice, R, p);
    const auto fused_kd = terra::rotated_distance(base, target, kd, R, p);
    CHECK(fused.mask_count == plain.mask_count);
    CHECK(fused.abs_sum == plain.abs_sum);  // same cells, same order: same bits
    CHECK(fused.distance == plain.distance);
    CHECK(fused_kd.mask_count == plain.mask_count);
    CHECK(fused_kd.distance == plain.distance);
  }
  // The true rotation scores better than the identity and than random rotations.
  const double at_truth = terra::rotated_distance(base, target, lattice, turn, p).distance;
  for (std::size_t k = 0; k < rotations.size(); ++k)
    if (k != 1)
      CHECK(at_truth < terra::rotated_distance(base, target, lattice, rotations[k], p).distance);
}

TEST_CASE("a descriptor against itself: zero distance over every far cell", "[distance]") {
  const terra::Lattice lattice(3000);
  const auto f = terra::make_descriptor(lattice, terra_test::scan(ulc::Mat3d::Identity()));
  const terra::DistanceParams p;
  const auto v =
      terra::rotated_distance(terra::base_cells(lattice, f, p.d1), terra::target_cells(f, p.d1),
                              lattice, ulc::Mat3d::Identity(), p);
  CHECK(v.distance == 0.0);
  CHECK(v.mask_count == f.cells_beyond(p.d1));
  CHECK(v.mask_count > 0);
}
