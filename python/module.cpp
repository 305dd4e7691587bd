// The Python module `ulc`: the calibration pipeline on numpy arrays, frame folders, cloud files
// and recordings, the stages on their own, the readers and the simulator (README, "From Python").
#include "bindings.hpp"
#include "ulc/version.hpp"

PYBIND11_MODULE(ulc, m) {
  namespace py = ulc::python::py;
  m.doc() =
      "ULC: universal LiDAR-to-LiDAR calibration (TERRA, JEEP, odometry, HOTS) on numpy arrays, "
      "frame folders, cloud files and recordings.";
  m.attr("__version__") = ULC_VERSION_STRING;
  ulc::python::bind_errors(m);
  ulc::python::bind_results(m);
  ulc::python::bind_calibrate(m);
  ulc::python::bind_io(m);
  ulc::python::bind_simulate(m);
  ulc::python::bind_terra(m);
  ulc::python::bind_jeep(m);
}
