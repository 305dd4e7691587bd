// Numbers written into the result's reasons and notes: fixed decimals, centimetres.
#pragma once

#include <cstdio>
#include <string>

namespace ulc {
namespace calibrate_detail {

inline std::string fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

inline std::string cm(double metres) {
  return fixed(metres * 100.0, 1) + " cm";
}

}  // namespace calibrate_detail
}  // namespace ulc
