// A user's file that calibrates its own point type: what scripts/compile_time.sh compiles.
// By default through pipeline/calibrate.hpp (the pipeline compiled once elsewhere: ulc::calibrate);
// with -DULC_IN_PLACE through calibrate_pair_in_place, every stage compiled for this type (the
// baseline of the same run).
#include <cstdint>
#include <vector>

#ifdef ULC_IN_PLACE
#include "pipeline/pipeline.hpp"
#else
#include "pipeline/calibrate.hpp"
#endif

struct VehiclePoint {
  float x, y, z;
  float intensity;
  std::uint16_t ring;
  double time;
};

ulc::PairCalibration calibrate_vehicle(const std::vector<std::vector<VehiclePoint>>& a,
                                       const std::vector<double>& ta,
                                       const std::vector<std::vector<VehiclePoint>>& b,
                                       const std::vector<double>& tb) {
#ifdef ULC_IN_PLACE
  return ulc::calibrate_pair_in_place(a, ta, b, tb);
#else
  return ulc::calibrate_pair(a, ta, b, tb);
#endif
}
