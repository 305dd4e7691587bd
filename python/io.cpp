// Reading clouds and recordings from Python: ulc.read_cloud (one .pcd/.ply/.bin file as stored)
// and ulc.read_frames (one LiDAR's frames and timestamps from any source `ulc calibrate` reads,
// through the same readers, so per-point times come out relative to each frame).
#include <pybind11/stl.h>

#include <optional>
#include <string>

#include "call_control.hpp"
#include "errors.hpp"
#include "frames.hpp"
#include "lidar_input.hpp"
#include "ulc/io/cloud_file.hpp"

namespace ulc::python {
namespace {

py::array_t<double> read_cloud(const std::string& path) {
  const PointCloud<float> cloud = with_cli_errors("read_cloud", [&] {
    return without_gil([&] { return io::read_cloud<PointCloud<float>>(path); });
  });
  return array_from_cloud(cloud);
}

py::dict read_frames(const std::string& source, std::size_t first, std::optional<std::size_t> count,
                     std::optional<double> start, std::optional<double> duration,
                     const std::string& frame_time) {
  return with_cli_errors("read_frames", [&] {
    const app::InputOptions options =
        app::input_options(start, duration, frame_time, "read_frames");
    const auto inputs = app::open_lidar_inputs(
        {app::parse_lidar_spec(source, "read_frames", "source")}, options, "read_frames");
    const app::LoadedFrames loaded =
        without_gil([&] { return inputs.front()->load(first, count.value_or(app::kAllFrames)); });
    py::list frames;
    for (const auto& cloud : loaded.clouds) frames.append(array_from_cloud(cloud));
    py::dict out;
    out["name"] = inputs.front()->name();
    out["frames"] = frames;
    out["times"] =
        py::array_t<double>(static_cast<py::ssize_t>(loaded.times.size()), loaded.times.data());
    out["warnings"] = inputs.front()->warnings();
    return out;
  });
}

}  // namespace

void bind_io(py::module_& m) {
  m.def("read_cloud", &read_cloud, py::arg("path"),
        "One .pcd, .ply or KITTI .bin file as an N x 3 array, or N x 4 with its per-point times "
        "(as stored). Unreadable files raise ulc.Error naming the file and the problem.");
  m.def("read_frames", &read_frames, py::arg("source"), py::kw_only(), py::arg("first") = 0,
        py::arg("count") = py::none(), py::arg("start") = py::none(),
        py::arg("duration") = py::none(), py::arg("frame_time") = "header",
        "One LiDAR's frames from a source `ulc calibrate` reads (a frame folder, a cloud file, "
        "FILE:TOPIC of a recording): {'name', 'frames': [N x 4 or N x 3 arrays, per-point times "
        "relative to the frame], 'times': frame timestamps (s, own clock), 'warnings'}.");
}

}  // namespace ulc::python
