// The degenerate verdict: does the final problem of a calibration pin down every direction of
// the extrinsic (ulc/core/observability.hpp)?
//
// Conventions this header owns:
//   - The final problem is HOTS's whole-sequence step (sequence_extrinsic.hpp: every target
//     frame against the base's submaps; its normal matrix for C) when it ran, whether HOTS then
//     succeeded or not; otherwise JEEP's final map-to-map registration (the acceptance's
//     agreeing points, jeep/acceptance.hpp) when its maps agree, static single frames included;
//     otherwise none, and nothing is judged (TERRA alone, a failed JEEP whose maps disagree, an
//     answer the free-space check refused as a look-alike of the scene: a misregistration's
//     information says nothing about the scene, and a look-alike's own free direction would
//     name the scene degenerate where the refusal names the true cause).
//   - When the final problem leaves a direction free, the status is degenerate whatever the
//     stages said (ok, jeep_failed, hots_failed): the scene is the cause, and on a straight
//     road or in a tunnel HOTS's time synchronisation fails or its result drifts along the
//     road for that reason. The reason names the directions in words and keeps the stages'
//     own failure, if any; the extrinsic stays the one the stages reached (its other
//     directions are the data's); `unobservable` holds the vectors.
//   - A degenerate verdict is reached at the end of the call, after TERRA's hypotheses: a
//     scene that leaves a direction free does so from every start, and the hypotheses' flow
//     (and every non-degenerate result) is unchanged.
#pragma once

#include <string>

#include "hots/refine_statistics.hpp"
#include "jeep/acceptance.hpp"
#include "pipeline/pair_calibration.hpp"
#include "ulc/core/observability.hpp"

namespace ulc {
namespace calibrate_detail {

/// JEEP's final registration's observability in the base frame, when its maps agree.
inline std::optional<Observability> jeep_observability(const jeep::AcceptanceReport& a,
                                                       const Isometry3d& C) {
  if (!a.maps_agree) return std::nullopt;
  if (!a.measured_a) return observability(a.information, a.centre, a.covariance);
  const Mat3d R = C.linear();
  return observability(information_in_base(a.information, C), C * a.centre,
                       Mat3d(R * a.covariance * R.transpose()));
}

/// The whole-sequence step's observability, when it ran.
inline std::optional<Observability> hots_observability(const hots::SequenceExtrinsicResult& s) {
  if (!s.ok()) return std::nullopt;
  return observability(s.information, s.centre, s.covariance);
}

/// "n direction(s) of the extrinsic ... : <words>; <words>".
inline std::string degenerate_reason(const std::vector<UnobservableDirection>& free,
                                     const std::string& problem) {
  std::string out = problem == "hots" ? "HOTS's whole-sequence registration"
                                      : "JEEP's final map-to-map registration";
  out += " leaves " + std::to_string(free.size()) + " direction" + (free.size() == 1 ? "" : "s") +
         " of the extrinsic free: ";
  for (std::size_t k = 0; k < free.size(); ++k) out += (k ? "; " : "") + free[k].words;
  return out +
         " (the other directions are determined; a drive with turns or a scene with structure "
         "across that direction pins it down)";
}

/// Fills r's observability fields from the final problem (see the conventions); when it leaves
/// a direction free, status becomes degenerate and the reason says which (keeping `reason`,
/// the stages' own failure, after it).
inline void judge_observability(PairCalibration& r, CalibrateStatus& status, std::string& reason) {
  const std::optional<Observability>* final_problem = nullptr;
  if (r.hots && r.hots->observability) {
    final_problem = &r.hots->observability;
    r.observability_problem = "hots";
  } else if (r.jeep && r.jeep->observability) {
    final_problem = &r.jeep->observability;
    r.observability_problem = "jeep";
  } else {
    return;
  }
  const Observability& o = **final_problem;
  r.weakest_share = o.weakest_share;
  r.unobservable = o.unobservable;
  // Idempotent: a call may be finished twice (the clock check of vouch.hpp runs after the
  // stages' own finish), and a degenerate verdict already holds its reason.
  if (!o.degenerate() || status == CalibrateStatus::degenerate) return;
  std::string why = degenerate_reason(o.unobservable, r.observability_problem);
  if (status != CalibrateStatus::ok) why += "; the stages themselves: " + reason;
  status = CalibrateStatus::degenerate;
  reason = std::move(why);
}

}  // namespace calibrate_detail
}  // namespace ulc
