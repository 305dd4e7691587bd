// The ground vote over a map window: a few of the target's window frames, each voted against
// the base's map re-anchored at the base frame nearest it in time, and the window's answer:
// pooled over the frames (the default, MotionFrameOptions::pool_votes) or the one most of the
// confident votes back (the tally). Not in the paper (issue 34).
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
//     last (count 1: the anchor frame alone, the map's own frame). Five frames so spaced
//     include the three (map_terra.hpp votes five where none of the three is sure).
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
//   - Pooled vote: every frame's refined peaks (GroundVoteResult::peaks) are the candidates;
//     each is scored on every frame that can vote (terra::pose_share: its share of votes near
//     the pose, a vote taken away for each point landing in free space the base's raw frame saw
//     when the input has it) and the mean over the frames is its pooled score. The best wins
//     (ties: the earlier frame's, then the earlier peak); its margin is over the best candidate
//     more than margin_separation_deg away, and it is confident under the single frame's
//     min_score and min_margin. Why: the mount's pose is the same in every frame while the
//     street's twin moves from frame to frame, and the road a twin puts points on is space the
//     base saw empty.
//   - The window's answer (window_answer): the tally's when it is sure and the pool's best lies
//     within conflict_deg of it (sure or not); none when the pool is sure of a rotation farther
//     off; the pool's when the tally is not sure, or when the pool, unsure, prefers a rotation
//     farther off (then the window is unsure, the pool's best its guess). Measured (2 s
//     windows, 50 per seed, seeds 1 / 2, within 10 deg; docs/experiments/terra_ground_vote.md,
//     "Pooling the window's frames"): 16-tele 70 / 74 % against 66 / 68 % tallied; the pool
//     alone reached 68 / 74 % there but lost 64-tele windows the tally had right (84 % against
//     88 % on seed 1: its margins 1.25-1.4 where the tally was sure, its best the tally's).
//     A sure tally the pool's best contradicts was the street's twin in 16-tele windows 40-42 of
//     seed 1 (one frame sure of it; the three frames together preferred the truth in two):
//     docs/experiments/terra_ground_vote.md, "An unsure pool as a guess".
//   - Nothing here throws or prints; deterministic (every vote is, and the pool's candidates
//     are scored into slots and reduced in order).
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

#include "terra/ground_vote.hpp"
#include "ulc/core/angles.hpp"
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

inline double gap_deg(const Mat3d& a, const Mat3d& b) {
  return rotation_error_rad(a, b) * 180.0 / kPi;
}
inline double gap_deg(const terra::GroundVoteResult& a, const terra::GroundVoteResult& b) {
  return gap_deg(a.rotation, b.rotation);
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

/// The window's pooled vote (see the conventions): the source frame's vote with the pooled
/// pose, score, margin and verdict (its points, plane and heights stay the source's own).
struct PooledVote {
  terra::GroundVoteResult vote;
  std::size_t source = 0;  ///< the voted frame whose peak won
};

namespace window_vote_detail {

/// Each peak of each frame, as (frame, peak index), in frame order.
inline std::vector<std::pair<std::size_t, std::size_t>> all_peaks(
    const std::vector<terra::GroundVoteResult>& votes) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  for (std::size_t f = 0; f < votes.size(); ++f)
    for (std::size_t k = 0; k < votes[f].peaks.size(); ++k) out.emplace_back(f, k);
  return out;
}

/// The mean share of a pose over the frames that can vote.
inline double pooled_share(const std::vector<terra::GroundVoteInput>& inputs,
                           const terra::GroundPose& pose, const terra::GroundVoteOptions& o) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const terra::GroundVoteInput& in : inputs)
    if (in.problem.empty()) sum += terra::pose_share(in, pose, o), ++n;
  return n > 0 ? sum / double(n) : 0.0;
}

}  // namespace window_vote_detail

/// Every frame's peaks scored on every frame; the best mean share wins, and its margin is over
/// the best peak more than margin_separation_deg away. `inputs[f]` is what `votes[f]` voted on.
inline PooledVote pool_votes(const std::vector<terra::GroundVoteInput>& inputs,
                             const std::vector<terra::GroundVoteResult>& votes,
                             const terra::GroundVoteOptions& o) {
  using namespace window_vote_detail;
  PooledVote out;
  const auto peaks = all_peaks(votes);
  if (peaks.empty()) {
    out.vote = votes.empty() ? terra::GroundVoteResult{} : votes.front();
    if (out.vote.reason.empty()) out.vote.reason = "no frame was voted";
    out.vote.ok = false;
    return out;
  }
  std::vector<double> pooled(peaks.size(), 0.0);
  tbb::parallel_for(std::size_t(0), peaks.size(), [&](std::size_t i) {
    pooled[i] = pooled_share(inputs, votes[peaks[i].first].peaks[peaks[i].second], o);
  });
  std::size_t win = 0;
  for (std::size_t i = 1; i < peaks.size(); ++i)
    if (pooled[i] > pooled[win]) win = i;
  const terra::GroundPose& best = votes[peaks[win].first].peaks[peaks[win].second];
  double rival = 0.0;
  for (std::size_t i = 0; i < peaks.size(); ++i) {
    const terra::GroundPose& p = votes[peaks[i].first].peaks[peaks[i].second];
    if (gap_deg(p.rotation, best.rotation) > o.margin_separation_deg)
      rival = std::max(rival, pooled[i]);
  }
  out.source = peaks[win].first;
  terra::GroundVoteResult& v = out.vote = votes[out.source];
  v.rotation = best.rotation;
  v.translation = best.translation;
  v.score = pooled[win];
  v.margin = rival > 0.0 ? v.score / rival : std::numeric_limits<double>::infinity();
  terra::judge_vote(v, o, "pooled over the window's frames: ");
  return out;
}

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

/// The window's answer with the pool beside the tally (see the conventions).
struct WindowAnswer {
  terra::GroundVoteResult vote;  ///< the answer (or, when none, the vote reported)
  VoteTally tally;               ///< ok and reason are the window's; chosen the frame reported
  bool pooled = false;           ///< the answer is the pool's
};

inline WindowAnswer window_answer(const std::vector<terra::GroundVoteResult>& votes,
                                  const VoteTally& tally, const PooledVote& pool,
                                  double conflict_deg) {
  using namespace window_vote_detail;
  WindowAnswer out{votes.empty() ? pool.vote : votes[tally.chosen], tally, false};
  // The pool's vote as the window's, sure or not as `ok` says.
  const auto pools = [&](bool ok, std::string reason) {
    out.vote = pool.vote;
    out.tally.ok = ok;
    out.tally.reason = std::move(reason);
    out.tally.chosen = pool.source;
    out.pooled = true;
    return out;
  };
  if (!tally.ok) return pools(pool.vote.ok, pool.vote.reason);
  const double gap = gap_deg(pool.vote, out.vote);
  if (!(gap > conflict_deg)) return out;
  const std::string apart = std::to_string(int(gap)) + " deg";
  if (!pool.vote.ok)
    return pools(false, "the frames' pool prefers, unsure, a rotation " + apart +
                            " from their tally's: " + pool.vote.reason);
  out.tally.ok = false;
  out.tally.reason = "the frames' tally and their pool are sure of rotations " + apart + " apart";
  return out;
}

}  // namespace ulc
