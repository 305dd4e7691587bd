// The options of TERRA's hypotheses (terra_hypotheses.hpp) and of how the pipeline judges the
// attempts started from them (pipeline.hpp). Light: no algorithm. None of this is in the paper,
// whose TERRA hands its single best rotation on.
#pragma once

#include <cstddef>

namespace ulc {

struct HypothesisOptions {
  /// When HOTS runs on a moving rig and the stages after TERRA's best rotation fail in a way
  /// that points at the rotation (JEEP fails, or HOTS finds the LiDARs' views disagree with it:
  /// extrinsic_unconfirmed), the search's next distinct optima are tried in turn, up to this
  /// many in all; the first success wins. 1 = the paper's single answer.
  std::size_t count = 4;
  /// ... and when all of those fail, up to this many more (terra_hypotheses.hpp,
  /// fallback_hypotheses): the kept search's remaining optima, then the other search's when
  /// both ran. With jeep among the stages, each must pass JEEP's own acceptance before HOTS
  /// runs from it (no hand-over: lower-ranked optima get the stricter test, and a refused one
  /// costs JEEP alone, 1-4 s); HOTS's cross links judge every one. 0 = none.
  std::size_t fallback = 8;
  /// Optima closer than this to a better one are the same hypothesis (JEEP converges from a few
  /// degrees).
  double separation_deg = 10.0;
  /// When HOTS runs on a moving rig, its cross links judge JEEP's extrinsic, not JEEP's own
  /// acceptance: a JEEP that settled but was rejected, or did not settle, hands its extrinsic
  /// to HOTS, and only HOTS's refusal (extrinsic_unconfirmed) ends the attempt. On narrow-FoV
  /// targets JEEP's acceptance refuses right extrinsics (the seven-LiDAR rig's Tele,
  /// docs/experiments/terra_hypotheses.md), while the cross links separate right from wrong.
  /// false: any JEEP failure ends the attempt.
  bool hots_judges_jeep = true;
  /// A static snapshot (no HOTS to judge): when the first hypothesis's answer is accepted by JEEP
  /// and judged and passed by the free-space check, up to this many next hypotheses run too and
  /// of the answers passing both the one seeing most of the scene off the ground wins
  /// (hypothesis_attempts.hpp).
  /// Over the parked census (bench_covariance --parked, seeds 1-20) it turned no right answer
  /// wrong and mended flicar-lift seed 17's two twins (docs/experiments/free_space_check.md);
  /// it costs one JEEP on one frame pair per rival. 0 = the first accepted answer stands.
  std::size_t snapshot_rivals = 3;
};

}  // namespace ulc
