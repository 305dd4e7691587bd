// The options of the automatic choice of HOTS's odometry (pipeline/odometry_choice.hpp, whose
// conventions give the reasons for the defaults).
#pragma once

#include <cstddef>

namespace ulc {

struct OdometryChoiceOptions {
  double min_duration_s = 30.0;       ///< the base's frames last at least this (seconds)
  double min_azimuth_coverage = 0.9;  ///< share of the azimuth sectors holding a point
  std::size_t azimuth_sectors = 72;   ///< 5 degrees each
  double min_range_m = 2.0;           ///< horizontal; nearer points are the vehicle itself
};

}  // namespace ulc
