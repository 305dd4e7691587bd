// LidarInput: where one LiDAR's frames come from on the command line, whatever the storage.
//
//   PATH              a frame folder or one cloud file (.pcd .ply .bin), as io::Sequence reads it
//   FILE:TOPIC        a topic of a recording: a ROS 1 .bag, an .mcap, a rosbag2 folder or a .db3
//   FILE              a recording with a single point-cloud topic
//   ...=NAME          any of the above, named NAME in the result file
// Default names: a folder's name, a file's stem, a topic's frame_id. Names that repeat get their
// parent folder (files), or become the topic (topics sharing a frame_id); a clash that remains
// is an error asking for =NAME.
//
// --start S --duration D keep the frames from S seconds after the recording's first message (a
// folder's first frame) for D seconds; they apply to every LiDAR.
#pragma once

#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ulc/core/frame_source.hpp"
#include "ulc/core/point_cloud.hpp"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace ulc::app {

/// Frames all held, and their times (Python's read_frames returns them all).
struct LoadedFrames {
  std::vector<PointCloud<float>> clouds;  ///< per-point times relative to the frame
  std::vector<double> times;              ///< seconds, the LiDAR's own clock
};

/// Frames read on demand (ulc/core/frame_source.hpp) and their times.
struct StreamedFrames {
  std::unique_ptr<FrameSource> frames;
  std::vector<double> times;  ///< seconds, the LiDAR's own clock
};

struct LidarSpec {
  std::string text;   ///< as given on the command line
  std::string path;   ///< folder, cloud file or recording
  std::string topic;  ///< empty: no topic given
  std::string name;   ///< empty: the default name
};

/// Splits "PATH[:TOPIC][=NAME]" (see the top of this file). UsageError naming `option`.
LidarSpec parse_lidar_spec(const std::string& text, const std::string& command,
                           const std::string& option);

struct InputWindow {
  std::optional<double> start_s;     ///< seconds after the recording's first message
  std::optional<double> duration_s;  ///< seconds
};

enum class FrameTimeChoice { header_stamp, receive_time };

struct InputOptions {
  InputWindow window;
  FrameTimeChoice frame_time = FrameTimeChoice::header_stamp;  ///< recordings only
};

constexpr std::size_t kAllFrames = std::numeric_limits<std::size_t>::max();

class LidarInput {
 public:
  virtual ~LidarInput() = default;
  const std::string& name() const { return name_; }
  void set_name(std::string name) { name_ = std::move(name); }

  /// "drive.bag:/points" or the folder, for messages.
  virtual std::string source() const = 0;
  /// The name to take when the default name repeats: the parent folder joined to a file's or
  /// folder's name, a recording's topic.
  virtual std::string name_when_repeated() const = 0;
  /// Returns false to stop early.
  using FrameVisitor = std::function<bool(PointCloud<float>&& cloud, double time)>;
  /// Reads frames first .. first + count - 1 of the selection (fewer when it ends first) one at a
  /// time, in time order, handing each to `visit`.
  virtual void visit(std::size_t first, std::size_t count, const FrameVisitor& visit) const = 0;
  /// The same frames, all held.
  LoadedFrames load(std::size_t first, std::size_t count) const {
    LoadedFrames out;
    visit(first, count, [&out](PointCloud<float>&& cloud, double time) {
      out.clouds.push_back(std::move(cloud));
      out.times.push_back(time);
      return true;
    });
    return out;
  }
  /// The same frames, read on demand: a folder reads each file when a stage asks for it; a
  /// recording, which reads only in order, is copied once into a temporary file (frame_spool.hpp).
  virtual StreamedFrames stream(std::size_t first, std::size_t count) const;
  /// The frames' times when known without reading them (a folder's), else empty.
  virtual std::vector<double> frame_times() const { return {}; }
  /// Seconds from the first frame to the last.
  virtual double span_s() const = 0;
  /// Median frame period in seconds (0 when unknown), for pairing frame counts.
  virtual double period() const = 0;
  /// What the reader had to work around (an unindexed bag, ...), one line each.
  virtual std::vector<std::string> warnings() const { return {}; }

 protected:
  std::string name_;
};

/// Opens every LiDAR and gives each a unique name (see the top). Recordings named by several
/// specs are opened once. Throws io::IoError for unreadable input, UsageError for clashes.
std::vector<std::unique_ptr<LidarInput>> open_lidar_inputs(const std::vector<LidarSpec>& specs,
                                                           const InputOptions& options,
                                                           const std::string& command);

/// --start, --duration and --frame-time as given on the command line.
struct InputArgs {
  CLI::Option* start = nullptr;     ///< given when count() > 0; nullptr: not declared
  CLI::Option* duration = nullptr;  ///< as start
  double start_s = 0.0;
  double duration_s = 0.0;
  std::string frame_time = "header";
};

/// Declares --start, --duration and --frame-time on a command's options.
void add_input_options(CLI::App& app, InputArgs& args);
/// Declares --frame-time alone.
void add_frame_time_option(CLI::App& app, InputArgs& args);
/// Reads them back (UsageError for a negative start or a duration that is not positive).
InputOptions input_options(const InputArgs& args, const std::string& command);
/// The same from values (unset: not given); frame_time is "header" or "receive".
InputOptions input_options(std::optional<double> start_s, std::optional<double> duration_s,
                           const std::string& frame_time, const std::string& command);

/// Prints each input's warnings on stderr as "ulc COMMAND: warning: SOURCE: ...".
void print_input_warnings(const std::vector<std::unique_ptr<LidarInput>>& inputs,
                          const std::string& command);

}  // namespace ulc::app
