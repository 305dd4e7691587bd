// The one instantiation of the pipeline on the simulator's frames that the other test files
// share (declared extern in calibrate_test_util.hpp).
#include "calibrate_test_util.hpp"

template ulc::PairCalibration
ulc::calibrate_pair<calibrate_test::SimFrames, calibrate_test::SimFrames>(
    const calibrate_test::SimFrames&, const std::vector<double>&, const calibrate_test::SimFrames&,
    const std::vector<double>&, const ulc::CalibrateOptions&);
