// ulc.terra.search: TERRA on its own (terra/search.hpp), the rotation R_base_target between two
// clouds with no guess (the paper's two-step search over the spherical descriptors).
#include "call_control.hpp"
#include "errors.hpp"
#include "frames.hpp"
#include "terra/search.hpp"

namespace ulc::python {
namespace {

py::array_t<double> array_from_matrix(const Mat3d& R) {
  py::array_t<double> out({3, 3});
  auto v = out.mutable_unchecked<2>();
  for (py::ssize_t r = 0; r < 3; ++r)
    for (py::ssize_t c = 0; c < 3; ++c) v(r, c) = R(r, c);
  return out;
}

py::dict search(const py::handle& base, const py::handle& target, std::size_t lattice_size,
                double d1, double d2, double alpha, std::size_t threads,
                const py::object& progress) {
  const PointCloud<float> a = cloud_from_python(base, "ulc terra.search: base");
  const PointCloud<float> b = cloud_from_python(target, "ulc terra.search: target");
  terra::SearchParams params;
  params.lattice_size = lattice_size;
  params.distance.d1 = d1;
  params.distance.d2 = d2;
  params.distance.alpha = alpha;
  const CalibrateProgress hook = python_progress(progress);
  params.progress = [&hook](double f) { hook("terra", f); };
  const terra::SearchResult r = without_gil(
      [&] { return in_arena(threads, [&] { return terra::estimate_rotation(a, b, params); }); });
  py::dict out;
  out["status"] = terra::to_string(r.status);
  out["reason"] = r.reason;
  out["success"] = r.ok();
  out["rotation"] = array_from_matrix(r.rotation);
  out["distance"] = r.distance;
  out["mask_count"] = r.mask_count;
  out["d1_used_m"] = r.stats.d1_used;
  out["rotations_evaluated"] = r.stats.rotations();
  out["seconds"] = r.stats.seconds() + r.stats.descriptor_seconds;
  return out;
}

}  // namespace

void bind_terra(py::module_& m) {
  py::module_ terra = m.def_submodule("terra", "TERRA: the rotation between two LiDARs, no guess");
  terra.def("search", &search, py::arg("base"), py::arg("target"), py::kw_only(),
            py::arg("lattice_size") = terra::SearchParams{}.lattice_size,
            py::arg("d1") = terra::DistanceParams{}.d1, py::arg("d2") = terra::DistanceParams{}.d2,
            py::arg("alpha") = terra::DistanceParams{}.alpha, py::arg("threads") = 0,
            py::arg("progress") = py::none(),
            "R_base_target (p_base ~ R p_target) between one frame of each LiDAR (N x 3 or N x 4 "
            "arrays): {'status', 'reason', 'success', 'rotation' (3x3), 'distance' "
            "(eq:feature_dis), 'mask_count' (eq:mask cells), 'd1_used_m', "
            "'rotations_evaluated', 'seconds'}. N, d1, d2, alpha as in the paper's table.");
}

}  // namespace ulc::python
