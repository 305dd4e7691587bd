// How a JEEP run ended (jeep.hpp), apart from the algorithm so that reports stay light.
#pragma once

namespace jeep {

enum class JeepStatus {
  ok,
  not_converged,        ///< max_rounds without settling
  rejected,             ///< settled, but the acceptance rule says the result is not trustworthy
  registration_failed,  ///< the calibration phase or a pose step had too few correspondences
  too_few_frames,       ///< no frame pair
  invalid_input         ///< bad options, timestamps, counts or initial extrinsic
};

inline const char* to_string(JeepStatus s) {
  switch (s) {
    case JeepStatus::ok:
      return "ok";
    case JeepStatus::not_converged:
      return "not_converged";
    case JeepStatus::rejected:
      return "rejected";
    case JeepStatus::registration_failed:
      return "registration_failed";
    case JeepStatus::too_few_frames:
      return "too_few_frames";
    default:
      return "invalid_input";
  }
}

}  // namespace jeep
