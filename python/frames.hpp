// numpy arrays as the pipeline's frames, and back.
//
// A frame is an N x 3 (x y z, metres) or N x 4 array (4th column: each point's time in seconds
// relative to the frame's timestamp), float32 or float64, of any strides. It is checked once
// with the GIL held (array_frame: shape, dtype, finite values) and its buffer recorded; read_frame
// then reads it, straight from that buffer, into the ulc::PointCloud<float> the compiled pipeline
// runs on, on any thread, without the GIL. An object with a `points` attribute (an Open3D
// PointCloud) is read through numpy.asarray(obj.points).
// Frames of one LiDAR: a list (or tuple) of frames, or one frame alone (a static rig).
#pragma once

#include <pybind11/numpy.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "pipeline/calibrate.hpp"

namespace ulc::python {

/// One checked frame's buffer: `array` keeps it alive, the rest is read without the GIL.
struct ArrayFrame {
  py::array array;
  const char* data = nullptr;
  std::size_t rows = 0;
  py::ssize_t row_stride = 0, column_stride = 0;  ///< bytes
  bool float64 = false;                           ///< else float32
  bool timed = false;                             ///< N x 4: the 4th column is each point's time
};

/// One frame, checked (GIL held); ulc.Error naming `what` for a wrong shape, dtype or a
/// non-finite value.
ArrayFrame array_frame(const py::handle& frame, const std::string& what);
/// One LiDAR's frames, checked (GIL held): a list of frames or one frame alone.
std::vector<ArrayFrame> array_frames(const py::handle& frames, const std::string& what);
/// The frame as the pipeline's cloud; needs no GIL.
PointCloud<float> read_frame(const ArrayFrame& frame);
/// One frame, read at once.
PointCloud<float> cloud_from_python(const py::handle& frame, const std::string& what);
/// One LiDAR's frames, read at once.
FloatFrames frames_from_python(const py::handle& frames, const std::string& what);
/// One timestamp per frame (seconds, increasing); none given: only for a single frame (0).
std::vector<double> times_from_python(const py::handle& times, std::size_t frames,
                                      const std::string& what);
/// N x 4 float64 (x y z t) when the cloud has per-point times, else N x 3.
py::array_t<double> array_from_cloud(const PointCloud<float>& cloud);
/// A 4x4 float64 array of a transform.
py::array_t<double> array_from_isometry(const Isometry3d& T);
/// A 4x4 array as a rigid transform; ulc.Error naming `what` otherwise.
Isometry3d isometry_from_python(const py::handle& matrix, const std::string& what);

}  // namespace ulc::python
