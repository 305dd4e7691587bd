// How an odometry run ended (run_odometry.hpp), apart from the algorithm so that reports stay
// light.
#pragma once

namespace odometry {

enum class OdometryStatus { ok, invalid_input, no_pairs, registration_failed };

inline const char* to_string(OdometryStatus s) {
  switch (s) {
    case OdometryStatus::ok:
      return "ok";
    case OdometryStatus::invalid_input:
      return "invalid_input";
    case OdometryStatus::no_pairs:
      return "no_pairs";
    default:
      return "registration_failed";
  }
}

}  // namespace odometry
