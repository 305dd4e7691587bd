// The parts of the Python module `ulc`, one file each (module.cpp puts them together).
#pragma once

#include <pybind11/pybind11.h>

namespace ulc::python {

namespace py = pybind11;

void bind_errors(py::module_& m);     ///< ulc.Error
void bind_results(py::module_& m);    ///< ulc.Result, ulc.RigResult
void bind_calibrate(py::module_& m);  ///< ulc.calibrate
void bind_io(py::module_& m);         ///< ulc.read_cloud, ulc.read_frames
void bind_simulate(py::module_& m);   ///< ulc.simulate, ulc.scenarios
void bind_terra(py::module_& m);      ///< ulc.terra.search
void bind_jeep(py::module_& m);       ///< ulc.jeep.run

}  // namespace ulc::python
