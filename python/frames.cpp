#include "frames.hpp"

#include <pybind11/stl.h>

#include <cmath>
#include <cstring>

#include "errors.hpp"

namespace ulc::python {
namespace {

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// Value (row, column) of the frame's buffer.
template <class Scalar>
double value_at(const ArrayFrame& f, std::size_t row, py::ssize_t column) {
  const char* at = f.data + static_cast<py::ssize_t>(row) * f.row_stride + column * f.column_stride;
  Scalar v;
  std::memcpy(&v, at, sizeof v);
  return static_cast<double>(v);
}

double value_at(const ArrayFrame& f, std::size_t row, py::ssize_t column) {
  return f.float64 ? value_at<double>(f, row, column) : value_at<float>(f, row, column);
}

/// The first row with a non-finite value, or rows when there is none.
std::size_t first_non_finite(const ArrayFrame& f) {
  const py::ssize_t columns = f.timed ? 4 : 3;
  for (std::size_t i = 0; i < f.rows; ++i)
    for (py::ssize_t c = 0; c < columns; ++c)
      if (!std::isfinite(value_at(f, i, c))) return i;
  return f.rows;
}

/// The frame's rows as a cloud, its values of type Scalar.
template <class Scalar>
PointCloud<float> read_rows(const ArrayFrame& f) {
  PointCloud<float> cloud;
  cloud.points.resize(f.rows);
  if (f.timed) cloud.times.resize(f.rows);
  for (std::size_t i = 0; i < f.rows; ++i) {
    cloud.points[i] = Eigen::Vector3f(static_cast<float>(value_at<Scalar>(f, i, 0)),
                                      static_cast<float>(value_at<Scalar>(f, i, 1)),
                                      static_cast<float>(value_at<Scalar>(f, i, 2)));
    if (f.timed) cloud.times[i] = value_at<Scalar>(f, i, 3);
  }
  return cloud;
}

/// The object itself when it is an array, else numpy.asarray of its points (Open3D), else of it.
py::array as_array(const py::handle& obj) {
  if (py::isinstance<py::array>(obj)) return py::reinterpret_borrow<py::array>(obj);
  const py::module_ numpy = py::module_::import("numpy");
  if (py::hasattr(obj, "points")) return numpy.attr("asarray")(obj.attr("points"));
  return numpy.attr("asarray")(obj);
}

bool is_frame_like(const py::handle& obj) {
  if (py::hasattr(obj, "points") && !py::isinstance<py::list>(obj)) return true;
  return py::isinstance<py::array>(obj) && py::reinterpret_borrow<py::array>(obj).ndim() == 2;
}

}  // namespace

ArrayFrame array_frame(const py::handle& frame, const std::string& what) {
  py::array a;
  try {
    a = as_array(frame);
  } catch (const py::error_already_set&) {
    raise_error(what + ": expected an N x 3 or N x 4 array");
  }
  if (a.ndim() != 2 || (a.shape(1) != 3 && a.shape(1) != 4))
    raise_error(what + ": expected an N x 3 or N x 4 array (x y z [t]), got shape " +
                shape_text(a));
  ArrayFrame f;
  f.float64 = a.dtype().is(py::dtype::of<double>());
  if (!f.float64 && !a.dtype().is(py::dtype::of<float>()))
    raise_error(what + ": expected float32 or float64 values, got " +
                py::str(a.dtype()).cast<std::string>());
  f.data = static_cast<const char*>(a.data());
  f.rows = static_cast<std::size_t>(a.shape(0));
  f.row_stride = a.strides(0);
  f.column_stride = a.strides(1);
  f.timed = a.shape(1) == 4;
  f.array = std::move(a);
  if (const std::size_t row = first_non_finite(f); row != f.rows)
    raise_error(what + ": row " + std::to_string(row) + " is not finite (drop NaN points first)");
  return f;
}

std::vector<ArrayFrame> array_frames(const py::handle& frames, const std::string& what) {
  std::vector<ArrayFrame> out;
  if (is_frame_like(frames)) {
    out.push_back(array_frame(frames, what + " frame 0"));
    return out;
  }
  if (!py::isinstance<py::sequence>(frames) || py::isinstance<py::str>(frames))
    raise_error(what + ": expected a list of N x 3 or N x 4 arrays, or one such array");
  const auto list = py::reinterpret_borrow<py::sequence>(frames);
  if (list.size() == 0) raise_error(what + ": no frames");
  for (std::size_t k = 0; k < list.size(); ++k)
    out.push_back(array_frame(list[k], what + " frame " + std::to_string(k)));
  return out;
}

PointCloud<float> read_frame(const ArrayFrame& f) {
  return f.float64 ? read_rows<double>(f) : read_rows<float>(f);
}

PointCloud<float> cloud_from_python(const py::handle& frame, const std::string& what) {
  return read_frame(array_frame(frame, what));
}

FloatFrames frames_from_python(const py::handle& frames, const std::string& what) {
  FloatFrames out;
  for (const ArrayFrame& f : array_frames(frames, what)) out.push_back(read_frame(f));
  return out;
}

std::vector<double> times_from_python(const py::handle& times, std::size_t frames,
                                      const std::string& what) {
  if (times.is_none()) {
    if (frames == 1) return {0.0};
    raise_error(what + ": " + std::to_string(frames) +
                " frames need their timestamps (one per frame, seconds)");
  }
  std::vector<double> out;
  try {
    out = py::module_::import("numpy")
              .attr("asarray")(times, py::dtype::of<double>())
              .attr("ravel")()
              .attr("tolist")()
              .cast<std::vector<double>>();
  } catch (const py::error_already_set&) {
    raise_error(what + ": expected one number per frame");
  }
  if (out.size() != frames)
    raise_error(what + ": " + std::to_string(out.size()) + " timestamps for " +
                std::to_string(frames) + " frames");
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (!std::isfinite(out[k]))
      raise_error(what + ": timestamp " + std::to_string(k) + " is not finite");
    if (k > 0 && !(out[k] > out[k - 1]))
      raise_error(what + ": timestamp " + std::to_string(k) + " does not increase");
  }
  return out;
}

py::array_t<double> array_from_cloud(const PointCloud<float>& cloud) {
  const bool timed = cloud.has_times();
  const py::ssize_t n = static_cast<py::ssize_t>(cloud.size()), cols = timed ? 4 : 3;
  py::array_t<double> out({n, cols});
  auto v = out.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& p = cloud.points[static_cast<std::size_t>(i)];
    for (py::ssize_t c = 0; c < 3; ++c) v(i, c) = p[c];
    if (timed) v(i, 3) = cloud.times[static_cast<std::size_t>(i)];
  }
  return out;
}

py::array_t<double> array_from_isometry(const Isometry3d& T) {
  py::array_t<double> out({4, 4});
  auto v = out.mutable_unchecked<2>();
  for (py::ssize_t r = 0; r < 4; ++r)
    for (py::ssize_t c = 0; c < 4; ++c) v(r, c) = T.matrix()(r, c);
  return out;
}

Isometry3d isometry_from_python(const py::handle& matrix, const std::string& what) {
  py::array_t<double> a;
  try {
    a = py::array_t<double, py::array::forcecast>::ensure(matrix);
  } catch (const py::error_already_set&) {
  }
  if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    raise_error(what + ": expected a 4x4 matrix");
  const auto v = a.unchecked<2>();
  Isometry3d T = Isometry3d::Identity();
  for (py::ssize_t r = 0; r < 3; ++r)
    for (py::ssize_t c = 0; c < 4; ++c) T.matrix()(r, c) = v(r, c);
  const Mat3d R = T.linear();
  if (!T.matrix().allFinite() || (R.transpose() * R - Mat3d::Identity()).norm() > 1e-6 ||
      R.determinant() < 0.0)
    raise_error(what + ": not a rigid transform (its rotation is not orthonormal)");
  return T;
}

}  // namespace ulc::python
