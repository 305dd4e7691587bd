#include "results.hpp"

#include <pybind11/stl.h>

#include <vector>

#include "errors.hpp"
#include "frames.hpp"
#include "ulc/io/result_yaml.hpp"

namespace ulc::python {
namespace {

/// A JSON value as Python objects (dicts, lists, numbers, strings, None).
py::object to_python(const io::Json& j) {
  return py::module_::import("json").attr("loads")(io::dump_json(j));
}

py::object optional_number(const std::optional<double>& v) {
  return v ? py::object(py::float_(*v)) : py::object(py::none());
}

py::object covariance(const io::PairResult& r) {
  if (!r.covariance_6x6) return py::none();
  py::array_t<double> out({6, 6});
  auto v = out.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < 6; ++i)
    for (py::ssize_t k = 0; k < 6; ++k) v(i, k) = (*r.covariance_6x6)(i, k);
  return std::move(out);
}

std::string json_text(const io::ResultDocument& d) {
  return io::dump_json(io::results_to_json(d.results, d.cycles)) + "\n";
}

/// Writes the document as `ulc calibrate --output PATH [--format FORMAT]` does (atomically).
void write(const io::ResultDocument& d, const std::string& path, const std::string& format) {
  if (format != "json" && format != "yaml")
    raise_error("ulc calibrate: option '--format': '" + format + "' is not json or yaml");
  with_cli_errors("calibrate", [&] {
    if (format == "yaml")
      io::write_result_yaml(path, d.results, d.cycles);
    else
      io::write_result_file(path, d.results, d.cycles);
  });
}

py::dict cycle_dict(const io::CycleResult& c) {
  py::dict d;
  d["lidars"] = c.lidars;
  d["status"] = c.status;
  d["reason"] = c.reason;
  d["rotation_deg"] = optional_number(c.rotation_deg);
  d["translation_m"] = optional_number(c.translation_m);
  return d;
}

void bind_result(py::module_& m) {
  py::class_<Result>(m, "Result",
                     "One target's calibration: the fields of its entry in the result file "
                     "(docs/design.md, \"Result file\").")
      .def_property_readonly("base", [](const Result& r) { return r.entry.base; })
      .def_property_readonly("target", [](const Result& r) { return r.entry.target; })
      .def_property_readonly("success", [](const Result& r) { return r.entry.success; })
      .def_property_readonly("status", [](const Result& r) { return r.entry.status; })
      .def_property_readonly("reason", [](const Result& r) { return r.entry.reason; })
      .def_property_readonly(
          "T_base_target",
          [](const Result& r) { return array_from_isometry(r.entry.T_base_target); },
          "4x4: p_base = T_base_target @ p_target (kept for inspection when success is False)")
      .def_property_readonly(
          "time_offset_s", [](const Result& r) { return optional_number(r.entry.time_offset_s); },
          "t_base_clock = t_target_clock + time_offset_s")
      .def_property_readonly("covariance_6x6", [](const Result& r) { return covariance(r.entry); })
      .def_property_readonly("stages", [](const Result& r) { return to_python(r.entry.stages); })
      .def_property_readonly("timing_s",
                             [](const Result& r) { return to_python(r.entry.timing_s); })
      .def_property_readonly("clock", [](const Result& r) { return to_python(r.entry.clock); })
      .def_property_readonly("point_times",
                             [](const Result& r) { return to_python(r.entry.point_times); })
      .def_property_readonly(
          "unobservable",
          [](const Result& r) { return to_python(io::unobservable_to_json(r.entry.unobservable)); })
      .def_property_readonly("via",
                             [](const Result& r) {
                               return r.entry.via.empty() ? py::object(py::none())
                                                          : py::object(py::str(r.entry.via));
                             })
      .def(
          "to_dict", [](const Result& r) { return to_python(io::to_json(r.entry)); },
          "the result file's entry as a dict")
      .def(
          "to_json",
          [](const Result& r) {
            return json_text({{r.entry}, {}});
          },
          "the result file of this pair, as `ulc calibrate --output` writes it")
      .def("to_yaml", [](const Result& r) { return io::results_to_yaml({r.entry}); })
      .def(
          "write",
          [](const Result& r, const std::string& path, const std::string& format) {
            write({{r.entry}, {}}, path, format);
          },
          py::arg("path"), py::arg("format") = "json")
      .def("__repr__", [](const Result& r) {
        return "<ulc.Result " + r.entry.base + " <- " + r.entry.target + ": " + r.entry.status +
               ">";
      });
}

void bind_rig_result(py::module_& m) {
  py::class_<RigResult>(m, "RigResult",
                        "A rig's calibration: one Result per target (input order) and the cycles "
                        "base -> i -> j -> base.")
      .def_property_readonly("results",
                             [](const RigResult& r) {
                               std::vector<Result> out;
                               for (const auto& e : r.document.results) out.push_back({e});
                               return out;
                             })
      .def_property_readonly("cycles",
                             [](const RigResult& r) {
                               py::list out;
                               for (const auto& c : r.document.cycles) out.append(cycle_dict(c));
                               return out;
                             })
      .def_property_readonly("success",
                             [](const RigResult& r) {
                               for (const auto& e : r.document.results)
                                 if (!e.success) return false;
                               return true;
                             })
      .def("to_json", [](const RigResult& r) { return json_text(r.document); })
      .def("to_yaml",
           [](const RigResult& r) {
             return io::results_to_yaml(r.document.results, r.document.cycles);
           })
      .def(
          "write",
          [](const RigResult& r, const std::string& path, const std::string& format) {
            write(r.document, path, format);
          },
          py::arg("path"), py::arg("format") = "json")
      .def("__repr__", [](const RigResult& r) {
        return "<ulc.RigResult " + std::to_string(r.document.results.size()) + " targets>";
      });
}

}  // namespace

void bind_results(py::module_& m) {
  bind_result(m);
  bind_rig_result(m);
}

}  // namespace ulc::python
