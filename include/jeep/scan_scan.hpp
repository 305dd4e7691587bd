// Scan-to-scan calibration, the paper's baseline (eq:calib_scan): one frame of each LiDAR,
// registered directly, C* = argmin_T d(S_a, T(S_b)).
//
// Conventions this header owns:
//   - The two scans are taken as they are (no motion is known from one frame pair: no deskew).
//   - Same registration as JEEP's calibration phase (map_registration.hpp: the target scan gets
//     PCA planes, coarse-to-fine stages from the initial C) and the same acceptance rule
//     (acceptance.hpp), so the two can be compared as the paper does.
#pragma once

#include <vector>

#include "jeep/acceptance.hpp"
#include "jeep/map_registration.hpp"
#include "jeep/options.hpp"
#include "odometry/scan_preparation.hpp"
#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace jeep {

enum class ScanScanStatus { ok, rejected, registration_failed, invalid_input };

inline const char* to_string(ScanScanStatus s) {
  switch (s) {
    case ScanScanStatus::ok:
      return "ok";
    case ScanScanStatus::rejected:
      return "rejected";
    case ScanScanStatus::registration_failed:
      return "registration_failed";
    default:
      return "invalid_input";
  }
}

struct ScanScanResult {
  ScanScanStatus status = ScanScanStatus::ok;
  const char* reason = "";
  Isometry3d extrinsic = Isometry3d::Identity();  ///< C = T_base_target
  RegistrationResult<double> registration;
  AcceptanceReport acceptance;
  bool ok() const { return status == ScanScanStatus::ok; }
};

/// Registers scan b to scan a from `initial` (C = T_base_target).
template <class CloudA, class CloudB>
ScanScanResult scan_to_scan(const CloudA& scan_a, const CloudB& scan_b, const Isometry3d& initial,
                            const ScanScanOptions& options = {}) {
  using S = ulc::traits::scalar_t<CloudA>;
  ScanScanResult result;
  result.extrinsic = initial;
  if (!initial.matrix().allFinite() || !odometry::valid_scan_options(options.scan) ||
      options.registration.stages.empty()) {
    result.status = ScanScanStatus::invalid_input;
    result.reason = "bad options or initial extrinsic";
    return result;
  }
  const ulc::Vec6d still = ulc::Vec6d::Zero();
  const auto a = odometry::prepare_scan<S>(scan_a, still, 0.0, options.scan);
  const auto b = odometry::prepare_scan<S>(scan_b, still, 0.0, options.scan);
  const auto target = map_target(a.dense, options.registration);
  result.registration = register_maps(b.dense, target, initial, options.registration);
  const auto status = result.registration.status;
  if (status == ulc::RegistrationStatus::too_few_correspondences ||
      status == ulc::RegistrationStatus::invalid_input) {
    result.status = ScanScanStatus::registration_failed;
    result.reason = result.registration.reason;
    return result;
  }
  result.extrinsic = result.registration.pose;
  result.acceptance =
      assess(a.dense, b.dense, target, options.registration, result.extrinsic, options.acceptance);
  if (!result.acceptance.accepted) {
    result.status = ScanScanStatus::rejected;
    result.reason = result.acceptance.reason;
  }
  return result;
}

}  // namespace jeep
