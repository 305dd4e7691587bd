#include "errors.hpp"

namespace ulc::python {
namespace {

/// ulc.Error; the module holds the reference.
py::handle g_error_type;

}  // namespace

void raise_error(const std::string& message) {
  PyErr_SetString(g_error_type.ptr(), message.c_str());
  throw py::error_already_set();
}

void bind_errors(py::module_& m) {
  const py::exception<app::UsageError> type(m, "Error", PyExc_ValueError);
  type.attr("__doc__") =
      "Bad input or usage: the message is the line the `ulc` command prints for it.";
  g_error_type = type;
}

}  // namespace ulc::python
