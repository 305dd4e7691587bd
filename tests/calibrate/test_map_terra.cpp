// TERRA on local maps (pipeline/map_terra.hpp) and calibrate_pair's choice between frames
// and maps (CalibrateOptions::tuning.terra_source.source), on a short simulated 64-tele drive: an
// HDL-64E base and a Livox Tele-15 target whose single frame fills ~50 lattice cells.
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <cstring>
#include <string>
#include <vector>

#include "calibrate_test_util.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/map_terra.hpp"
#include "terra/random_rotation.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/result_entry.hpp"
#include "ulc/sim/sim.hpp"

namespace {

using calibrate_test::kDeg;

/// 4.5 s of the seeded 64-tele town drive, every 4th point kept.
const ulc::sim::Dataset& drive_64_tele() {
  static const ulc::sim::Dataset d = [] {
    ulc::sim::SimulationOptions o;
    o.seconds = 4.5;
    o.seed = 1;
    o.decimation = 4;
    return ulc::sim::simulate(*ulc::sim::scenario("64-tele"), o).dataset;
  }();
  return d;
}

/// The first base frame at or after 1 s (the vehicle is moving by then).
std::size_t start_index(const ulc::sim::Dataset& d) {
  std::size_t i = 0;
  while (i < d.lidars[0].timestamps.size() && d.lidars[0].timestamps[i] < 1.0) ++i;
  return i;
}

double error_deg(const ulc::Mat3d& truth, const ulc::Mat3d& R) {
  return ulc::rotation_error_rad(truth, R) / kDeg;
}

ulc::CalibrateOptions terra_only(ulc::TerraSource source) {
  ulc::CalibrateOptions o;
  o.stages = {ulc::Stage::terra};
  o.tuning.terra_source.source = source;
  o.tuning.terra_source.maps.window_s = 3.0;
  return o;
}

bool same_bits(const ulc::Mat3d& a, const ulc::Mat3d& b) {
  return std::memcmp(a.data(), b.data(), 9 * sizeof(double)) == 0;
}

/// The Tele's frames turned by a rotation uniform on SO(3) (its points p become Q p), and
/// R_base_target of the turned Tele.
struct TurnedTele {
  std::vector<ulc::PointCloud<float>> frames;
  ulc::Mat3d truth;
};

TurnedTele turned_tele(const ulc::sim::Dataset& d, terra::SplitMix64& rng) {
  const ulc::Mat3d Q = terra::random_rotation(rng);
  TurnedTele t{d.lidars[1].frames, d.pairs.at(0).T_base_target.linear() * Q.transpose()};
  for (auto& f : t.frames)
    for (auto& p : f.points) p = (Q * p.cast<double>()).cast<float>();
  return t;
}

/// 2 s windows whose ground and travel is refused, so that the ground vote alone answers.
ulc::MapTerraOptions vote_alone_options() {
  ulc::MapTerraOptions o;
  o.window_s = 2.0;
  o.motion.max_travel_mismatch = 0.0;
  return o;
}

}  // namespace

TEST_CASE("TERRA on 3 s local maps finds the 64-tele rotation that single frames miss",
          "[calibrate][map_terra]") {
  const auto& d = drive_64_tele();
  REQUIRE(d.lidars.size() == 2);
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  const std::size_t i = start_index(d);
  REQUIRE(i + 31 < a.frames.size());
  REQUIRE(i + 31 < b.frames.size());
  // Frame i of each LiDAR was taken at about the same instant (the frame search's premise).
  REQUIRE(std::abs(a.timestamps[i] - b.timestamps[i]) < 0.05);
  const ulc::Mat3d truth = d.pairs.at(0).T_base_target.linear();

  auto run = [&](ulc::TerraSource s) {
    ulc::CalibrateOptions o = terra_only(s);
    o.frame_index = i;
    return ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
  };
  // Single frames: the Tele's ~50 cells overlap the 64's in ~13 at the truth, and chance
  // matches of 2-5 cells win eq:feature_dis (measured: ~145 deg off).
  const auto frames = run(ulc::TerraSource::frames);
  REQUIRE(frames.terra);
  CHECK(frames.terra->source == ulc::TerraSource::frames);
  CHECK(!frames.terra->base_map);
  CHECK(*frames.terra->frames_mask_count < 30);
  CHECK((!frames.success || error_deg(truth, frames.terra->rotation) > 10.0));

  // Local maps over 3 s (measured: 3.5 deg, ~140 cells in the mask).
  const auto maps = run(ulc::TerraSource::maps);
  REQUIRE(maps.success);
  REQUIRE(maps.terra);
  CHECK(maps.terra->source == ulc::TerraSource::maps);
  CHECK(error_deg(truth, maps.terra->rotation) < 5.0);
  CHECK(maps.terra->mask_count > 5 * *frames.terra->frames_mask_count);
  REQUIRE(maps.terra->base_map);
  REQUIRE(maps.terra->target_map);
  CHECK(maps.terra->base_map->frames == 31);  // 3 s at 10 Hz, both ends
  CHECK(maps.terra->target_map->frames == 31);
  CHECK(maps.terra->base_map->odometry_status == odometry::OdometryStatus::ok);
  CHECK(maps.terra->target_map->odometry_status == odometry::OdometryStatus::ok);
  CHECK(maps.terra->target_map->points > 0);
  CHECK(maps.terra->target_map->points <= ulc::MapTerraOptions().max_points);
  CHECK(maps.terra->base_points == maps.terra->base_map->points);
  CHECK(maps.T_base_target.linear() == maps.terra->rotation);

  // automatic: the frames overlap too little, so it tries the maps and keeps them; same answer.
  const auto automatic = run(ulc::TerraSource::automatic);
  REQUIRE(automatic.success);
  CHECK(automatic.terra->source == ulc::TerraSource::maps);
  CHECK(same_bits(automatic.terra->rotation, maps.terra->rotation));
  CHECK(*automatic.terra->frames_mask_count == *frames.terra->frames_mask_count);

  // The result entry says which source, with the maps' statistics.
  const ulc::io::PairResult r = ulc::io::to_pair_result(automatic, "lidar64", "tele");
  const auto& t = r.stages.at("terra");
  CHECK(t.at("source").get<std::string>() == "maps");
  CHECK(t.at("frames_mask_count").get<double>() ==
        static_cast<double>(*automatic.terra->frames_mask_count));
  CHECK(t.at("base_map").at("frames").get<double>() == 31.0);
  CHECK(t.at("target_map").at("points").get<double>() ==
        static_cast<double>(automatic.terra->target_map->points));
}

TEST_CASE("the motion frame gives the 64-tele rotation from 2 s, whatever the mount",
          "[calibrate][map_terra][motion_frame]") {
  const auto& d = drive_64_tele();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  const std::size_t i = start_index(d);
  terra::SplitMix64 rng(11);
  for (int k = 0; k < 2; ++k) {
    const auto [turned, truth] = turned_tele(d, rng);
    ulc::CalibrateOptions o;
    o.stages = {ulc::Stage::terra};
    o.frame_index = i;
    const auto c = ulc::calibrate_pair(a.frames, a.timestamps, turned, b.timestamps, o);
    REQUIRE(c.success);
    REQUIRE(c.terra->motion);
    const ulc::MotionReport& m = *c.terra->motion;
    INFO("motion: " << m.reason << ", search off by " << m.search_off_deg << " deg");
    REQUIRE(m.ok);
    CHECK(m.travel_base_m > 3.0);
    CHECK(std::abs(m.travel_base_m - m.travel_target_m) < 0.1 * m.travel_base_m);
    CHECK(m.planes_matched >= 1);
    // The single frames' search misses (a chance match of a few cells: the test above); the
    // motion frame overrules it, or the map search agrees with it.
    CHECK(error_deg(truth, m.rotation) < 10.0);
    CHECK(error_deg(truth, c.terra->rotation) < 10.0);
    CHECK(c.T_base_target.linear() == c.terra->rotation);
    CHECK(c.terra->hypotheses.front().motion == m.used);
    const ulc::io::PairResult r = ulc::io::to_pair_result(c, "lidar64", "tele");
    const auto& t = r.stages.at("terra");
    CHECK(t.at("motion").at("ok").get<bool>());
    CHECK(t.at("motion").at("used").get<bool>() == m.used);
    CHECK(t.at("hypotheses").at(0).at("source").get<std::string>() == (m.used ? "motion" : "maps"));
  }
}

TEST_CASE("automatic TERRA stays on frames for single frames and for well-overlapping frames",
          "[calibrate][map_terra]") {
  SECTION("one frame per LiDAR (a static snapshot) never builds maps") {
    const auto& d = drive_64_tele();
    const std::size_t i = start_index(d);
    const std::vector<ulc::PointCloud<float>> fa{d.lidars[0].frames[i]}, fb{d.lidars[1].frames[i]};
    const auto c =
        ulc::calibrate_pair(fa, {0.0}, fb, {0.0}, terra_only(ulc::TerraSource::automatic));
    REQUIRE(c.terra);
    CHECK(c.terra->source == ulc::TerraSource::frames);
    CHECK(!c.terra->base_map);
    CHECK(c.terra->source_reason.find("1 frame") != std::string::npos);
  }
  SECTION("64-32 frames overlap in hundreds of cells: kept where the maps' answer agrees") {
    const auto& d = calibrate_test::drive_64_32();
    const auto& a = *d.find("lidar64");
    const auto& b = *d.find("lidar32");
    ulc::CalibrateOptions o = terra_only(ulc::TerraSource::automatic);
    o.tuning.terra_source.maps_min_frames =
        2;  // the 0.6 s drive has 6 frames: maps would be possible
    const auto c = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
    REQUIRE(c.success);
    CHECK(*c.terra->frames_mask_count >= o.tuning.terra_source.maps_below_mask);
    // The maps are built for the motion frame; the frames stand where it agrees with them
    // (within agree_for(method)), else its answer is the first hypothesis.
    REQUIRE(c.terra->motion);
    const ulc::MotionReport& m = *c.terra->motion;
    CHECK(m.ok);
    const bool agrees = m.search_off_deg <= o.tuning.terra_source.maps.motion.agree_for(m.method);
    INFO(m.method << ": the frames' answer " << m.search_off_deg << " deg off it");
    CHECK(m.used == !agrees);
    CHECK(c.terra->hypotheses.front().motion == m.used);
    if (agrees) CHECK(c.terra->source == ulc::TerraSource::frames);
    CHECK(error_deg(d.pairs.at(0).T_base_target.linear(), c.T_base_target.linear()) < 5.0);
  }
}

TEST_CASE("TERRA on local maps is identical for 1 and 2 threads", "[calibrate][map_terra]") {
  const auto& d = drive_64_tele();
  const std::size_t i = start_index(d);
  ulc::MapTerraOptions o;
  o.window_s = 1.0;
  const terra::Lattice lattice(10000);
  auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    return arena.execute([&] {
      return ulc::map_terra(lattice, d.lidars[0].frames, d.lidars[0].timestamps, d.lidars[1].frames,
                            d.lidars[1].timestamps, i, {}, o);
    });
  };
  const ulc::MapTerraResult one = run(1), two = run(2);
  REQUIRE(one.ok());
  CHECK(one.base.frames == 11);
  CHECK(one.base.points == two.base.points);
  CHECK(one.target.points == two.target.points);
  CHECK(one.search.mask_count == two.search.mask_count);
  CHECK(one.search.distance == two.search.distance);
  CHECK(same_bits(one.search.rotation, two.search.rotation));
}

TEST_CASE("a local map is the frames stacked in the anchor frame, thinned to its bound",
          "[calibrate][map_terra]") {
  const auto& d = drive_64_tele();
  const std::size_t i = start_index(d);
  const auto& a = d.lidars[0];
  ulc::MapTerraOptions o;
  o.window_s = 0.5;
  o.max_points = 20000;
  const auto map = ulc::build_local_map(a.frames, a.timestamps, i, o);
  REQUIRE(map.ok);
  CHECK(map.stats.frames == 6);
  CHECK(map.points.size() <= 20000);
  CHECK(map.stats.voxel_used > o.voxel);  // the bound forced a coarser voxel
  // The anchor is the last frame: its own (deskewed, thinned) frame lines up with the map, so
  // most of its points have a map point within a voxel or two.
  const auto& last = a.frames[i + 5];
  std::size_t near = 0, tried = 0;
  for (std::size_t k = 0; k < last.points.size(); k += 97) {
    const ulc::Vec3d p = last.points[k].cast<double>();
    if (p.norm() < 3.0 || p.norm() > 30.0) continue;
    ++tried;
    double best = 1e9;
    for (const auto& q : map.points) best = std::min(best, (q.cast<double>() - p).norm());
    near += best < 2.0 * map.stats.voxel_used;
  }
  REQUIRE(tried > 50);
  CHECK(static_cast<double>(near) > 0.8 * static_cast<double>(tried));
  // No window past the end.
  const auto none = ulc::build_local_map(a.frames, a.timestamps, a.frames.size(), o);
  CHECK(!none.ok);
  CHECK(none.points.empty());
}

TEST_CASE("the ground vote gives the 64-tele rotation from Tele frames, no target odometry",
          "[calibrate][map_terra][ground_vote]") {
  const auto& d = drive_64_tele();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  terra::SplitMix64 rng(12);
  const auto [turned, truth] = turned_tele(d, rng);
  const ulc::MapTerraOptions o = vote_alone_options();
  // Five windows 0.3 s apart: the vote answers where it is sure, and is right where it answers.
  std::size_t confident = 0;
  for (std::size_t k = 0; k < 5; ++k) {
    const std::size_t first = start_index(d) + 3 * k;
    const auto maps = ulc::build_local_maps(a.frames, a.timestamps, turned, b.timestamps, first, o);
    REQUIRE(maps.ok());
    // The base map's poses: one per window frame, the anchor (last) frame's the identity.
    REQUIRE(maps.a.poses.size() == maps.a.stats.frames);
    CHECK(maps.a.poses.back().isApprox(Eigen::Isometry3d::Identity(), 1e-12));
    const ulc::MotionReport& m = maps.motion;
    REQUIRE(m.vote_ran);
    INFO("window " << k << ": " << m.reason << "; chosen vote " << m.vote.reason << ", margin "
                   << m.vote.margin << ", score " << m.vote.score);
    // Three frames vote; five where none of the three was sure (unsure_vote_frames).
    CHECK((m.votes == 3 || m.votes == 5));
    if (m.votes_confident == 0) CHECK(m.votes == 5);
    CHECK(m.votes_agreeing <= m.votes_confident);
    // With the ground and travel refused, only a vote answers: sure, or the unsure pool's guess.
    CHECK(m.ok == (m.method == "ground vote" || m.method == "unsure ground vote"));
    if (m.method != "ground vote") continue;
    ++confident;
    CHECK(m.vote.ok);
    CHECK(m.votes_agreeing >= 1);
    CHECK(m.rotation == m.vote.rotation);
    CHECK(error_deg(truth, m.vote.rotation) < 3.0);
    // The target's height against the base's: the mounts differ by 0.2 m (scenario.hpp).
    CHECK(std::abs(m.vote.target_height - m.vote.base_height + 0.2) < 0.15);
  }
  CHECK(confident >= 1);
}

TEST_CASE("an unsure pooled vote stands in only where the ground and travel was refused",
          "[calibrate][map_terra][ground_vote]") {
  ulc::WindowAnswer unsure;
  unsure.pooled = true;
  unsure.tally.ok = false;
  unsure.vote.score = 0.3;
  unsure.vote.rotation = Eigen::AngleAxisd(1.0, ulc::Vec3d::UnitZ()).toRotationMatrix();
  ulc::MotionReport refused;
  refused.reason = "the rig travelled 0.1 m";
  SECTION("refused travel, enough votes landed: the pool's guess") {
    ulc::stand_in_unsure_vote(unsure, 0.1, refused);
    CHECK(refused.ok);
    CHECK(refused.method == "unsure ground vote");
    CHECK(refused.reason.empty());
    CHECK(refused.rotation == unsure.vote.rotation);
  }
  SECTION("too few votes landed: nothing") {
    ulc::stand_in_unsure_vote(unsure, 0.5, refused);
    CHECK_FALSE(refused.ok);
    CHECK(refused.reason == "the rig travelled 0.1 m");
  }
  SECTION("sure answers in conflict (not the pool's): nothing") {
    unsure.pooled = false;
    ulc::stand_in_unsure_vote(unsure, 0.1, refused);
    CHECK_FALSE(refused.ok);
  }
  SECTION("the ground and travel answered: it stays") {
    ulc::MotionReport travel;
    travel.ok = true;
    travel.method = "ground and travel";
    ulc::stand_in_unsure_vote(unsure, 0.1, travel);
    CHECK(travel.method == "ground and travel");
    CHECK(travel.rotation == ulc::Mat3d::Identity());
  }
}

TEST_CASE("where none of the first three frames is sure, five vote, as if voted from the start",
          "[calibrate][map_terra][ground_vote]") {
  const auto& d = drive_64_tele();
  const auto& a = d.lidars[0];
  const auto& b = d.lidars[1];
  terra::SplitMix64 rng(12);
  const auto turned = turned_tele(d, rng).frames;
  ulc::MapTerraOptions o = vote_alone_options();
  const auto motion = [&](const ulc::MapTerraOptions& options) {
    return ulc::build_local_maps(a.frames, a.timestamps, turned, b.timestamps, start_index(d),
                                 options)
        .motion;
  };
  SECTION("a sure frame among the first three: no second round") {
    const ulc::MotionReport m = motion(o);
    REQUIRE(m.vote_ran);
    REQUIRE(m.votes_confident >= 1);
    CHECK(m.votes == 3);
  }
  SECTION("none sure: five frames, the same answer as five from the start") {
    o.motion.vote.min_score = 2.0;  // more than every vote landing: none is sure
    const ulc::MotionReport twice = motion(o);
    REQUIRE(twice.vote_ran);
    CHECK(twice.votes == 5);
    CHECK(twice.votes_confident == 0);
    ulc::MapTerraOptions at_once = o;
    at_once.motion.vote_frames = 5;
    at_once.motion.unsure_vote_frames = 0;
    const ulc::MotionReport once = motion(at_once);
    CHECK(once.votes == 5);
    CHECK(twice.ok == once.ok);
    CHECK(twice.method == once.method);
    CHECK(twice.vote_frame == once.vote_frame);
    CHECK(twice.vote.score == once.vote.score);
    CHECK(same_bits(twice.rotation, once.rotation));
    CHECK(same_bits(twice.vote.rotation, once.vote.rotation));
    ulc::MapTerraOptions three = o;
    three.motion.unsure_vote_frames = 0;
    CHECK(motion(three).votes == 3);
  }
}
