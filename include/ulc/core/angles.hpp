// The circle's constant and the degree-radian conversions, defined once for every stage (the
// library reports angles in degrees and computes in radians).
#pragma once

namespace ulc {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kRadPerDeg = kPi / 180.0;
inline constexpr double kDegPerRad = 180.0 / kPi;

}  // namespace ulc
