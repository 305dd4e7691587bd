// The ground vote over a map window: a few of the target's window frames, each voted against
// the base's map re-anchored at the base frame nearest it in time, and the answer most of the
// confident votes back. Not in the paper (issue 34).
//
// Why several frames: a single frame votes well only where the base's map is dense around what
// it sees. The window's last frame (the map's anchor) looks ahead of the vehicle into what the
// base saw only from afar, while its first frame looks into what the base then drove through;
// a street's forward/backward twin wins where the map behind is denser than the map ahead.
// Measured (2 s windows, 50 per pair, seed 1; docs/experiments/terra_ground_vote.md), confident
// right / wrong answers: 16-tele last frame 1 / 4, first 13 / 1, first, middle and last with
// this tally 16 / 4; 64-tele 25 / 1, 34 / 0, 41 / 1; horizon-tele 41 / 2, 42 / 2, 44 / 2;
// 32-mid40 48 / 0, 45 / 0, 50 / 0.
//
// Conventions this header owns:
//   - Frames voted: `count` of the window's target frames evenly spaced from its first to its
//     last (count 1: the anchor frame alone, the map's own frame).
//   - Tally: each confident vote's support is the number of confident votes within agree_deg of
//     its rotation (itself included). The window's answer is the vote with the most support
//     (ties: the higher score, then the earlier frame); none when a confident vote more than
//     conflict_deg away has as much support (two frames sure of different rotations: the
//     street's twin), or when no vote is confident (then the highest-scoring vote is reported,
//     with its reason). Two frames sure of rotations between agree_deg and conflict_deg apart
//     back one answer, the higher-scoring: each vote calls rotations within its own
//     margin_separation_deg (20) one peak; refusing such pairs lost 7 windows of the Tele pairs
//     whose frames were 5-10 deg apart (docs/experiments/terra_ground_vote.md, "A sparse
//     base's rings").
//   - Nothing here throws or prints; deterministic (every vote is).
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include "terra/ground_vote_options.hpp"
#include "ulc/core/pose_error.hpp"

namespace ulc {

/// The window frames voted (see the conventions): indices into a window of `frames` frames.
inline std::vector<std::size_t> vote_frame_indices(std::size_t frames, std::size_t count,
                                                   std::size_t anchor) {
  if (frames == 0) return {};
  if (count <= 1 || frames == 1) return {std::min(anchor, frames - 1)};
  count = std::min(count, frames);
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < count; ++k) out.push_back(k * (frames - 1) / (count - 1));
  return out;
}

/// The window's answer among per-frame votes (see the conventions).
struct VoteTally {
  bool ok = false;
  std::string reason;         ///< why no answer, when not ok
  std::size_t chosen = 0;     ///< the vote reported (the answer when ok)
  std::size_t confident = 0;  ///< votes that were confident
  std::size_t agreeing = 0;   ///< confident votes within agree_deg of the answer
};

namespace window_vote_detail {

inline double gap_deg(const terra::GroundVoteResult& a, const terra::GroundVoteResult& b) {
  return rotation_error_rad(a.rotation, b.rotation) * 180.0 / 3.14159265358979323846;
}

inline std::size_t support(const std::vector<terra::GroundVoteResult>& votes, std::size_t i,
                           double agree_deg) {
  std::size_t n = 0;
  for (const terra::GroundVoteResult& v : votes) n += v.ok && gap_deg(v, votes[i]) <= agree_deg;
  return n;
}

/// The highest-scoring vote among those `keep` accepts (the earliest on ties).
template <class Keep>
std::size_t best_scoring(const std::vector<terra::GroundVoteResult>& votes, Keep keep) {
  std::size_t best = votes.size();
  for (std::size_t i = 0; i < votes.size(); ++i)
    if (keep(i) && (best == votes.size() || votes[i].score > votes[best].score)) best = i;
  return best;
}

}  // namespace window_vote_detail

inline VoteTally tally_votes(const std::vector<terra::GroundVoteResult>& votes, double agree_deg,
                             double conflict_deg) {
  using namespace window_vote_detail;
  VoteTally t;
  if (votes.empty()) return t.reason = "no frame was voted", t;
  std::vector<std::size_t> backing(votes.size(), 0);
  for (std::size_t i = 0; i < votes.size(); ++i) {
    t.confident += votes[i].ok;
    if (votes[i].ok) backing[i] = support(votes, i, agree_deg);
  }
  if (t.confident == 0) {
    t.chosen = best_scoring(votes, [](std::size_t) { return true; });
    t.reason = votes[t.chosen].reason;
    return t;
  }
  t.agreeing = *std::max_element(backing.begin(), backing.end());
  t.chosen = best_scoring(votes, [&](std::size_t i) { return backing[i] == t.agreeing; });
  for (std::size_t i = 0; i < votes.size(); ++i)
    if (backing[i] == t.agreeing && gap_deg(votes[i], votes[t.chosen]) > conflict_deg) {
      t.reason = "the window's frames are sure of rotations " +
                 std::to_string(int(gap_deg(votes[i], votes[t.chosen]))) + " deg apart (" +
                 std::to_string(t.agreeing) + " votes each)";
      return t;
    }
  t.ok = true;
  return t;
}

}  // namespace ulc
