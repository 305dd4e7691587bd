// Units the tests share: one definition, so that test folders built as one translation unit
// (tests/CMakeLists.txt) see a single kDeg through every helper namespace.
#pragma once

namespace ulc_test {

inline constexpr double kDeg = 3.14159265358979323846 / 180.0;

}  // namespace ulc_test
