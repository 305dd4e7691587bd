// Uses the installed compiled pipeline (ulc::calibrate): calibrate_pair on a user's own point
// type links, runs and says why it cannot calibrate frames that do not match their timestamps.
#include <cstdio>
#include <vector>

#include "pipeline/calibrate.hpp"

struct UserPoint {
  float x, y, z;
};

int main() {
  const std::vector<std::vector<UserPoint>> frames = {{{1, 2, 3}, {4, 5, 6}}};
  const std::vector<double> no_times;
  const ulc::PairCalibration r = ulc::calibrate_pair(frames, no_times, frames, no_times);
  const bool ok = !r.success && r.status == ulc::CalibrateStatus::invalid_input;
  std::printf("consumer_calibrate: %s (%s)\n", ok ? "ok" : "WRONG", r.reason.c_str());
  return ok ? 0 : 1;
}
