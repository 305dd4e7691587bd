// numpy arrays as the pipeline's frames, and back.
//
// A frame is an N x 3 (x y z, metres) or N x 4 array (4th column: each point's time in seconds
// relative to the frame's timestamp), float32 or float64, of any strides: it is read once,
// straight from its buffer, into the ulc::PointCloud<float> the compiled pipeline runs on (no
// intermediate copy, whatever the dtype or layout). An object with a `points` attribute (an
// Open3D PointCloud) is read through numpy.asarray(obj.points).
// Frames of one LiDAR: a list (or tuple) of frames, or one frame alone (a static rig).
#pragma once

#include <pybind11/numpy.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "pipeline/calibrate.hpp"

namespace ulc::python {

/// One frame; ulc.Error naming `what` for a wrong shape, dtype or a non-finite value.
PointCloud<float> cloud_from_python(const py::handle& frame, const std::string& what);
/// One LiDAR's frames.
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
