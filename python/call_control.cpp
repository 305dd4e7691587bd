#include "call_control.hpp"

#include <memory>
#include <string>

namespace ulc::python {

CalibrateProgress python_progress(py::object progress) {
  // Shared so that copies of the hook (the rig prefixes it per pair) keep one reference, and
  // released with the GIL held.
  auto callable =
      std::shared_ptr<py::object>(new py::object(std::move(progress)), [](py::object* o) {
        py::gil_scoped_acquire gil;
        delete o;
      });
  return [callable](const std::string& stage, double fraction) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!callable->is_none()) (*callable)(stage, fraction);
  };
}

}  // namespace ulc::python
