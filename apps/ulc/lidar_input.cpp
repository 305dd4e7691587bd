// The LiDAR inputs of the command line: frame folders and files (io::Sequence) and topics of
// recordings (ulc/bags), behind one interface (lidar_input.hpp).
#include "lidar_input.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "command_line.hpp"
#include "frame_spool.hpp"
#include "odometry/frame_pairing.hpp"
#include "ulc/bags/cloud_topic.hpp"
#include "ulc/bags/recording.hpp"
#include "ulc/io/decoded_cloud.hpp"
#include "ulc/io/sequence.hpp"

namespace ulc::app {
namespace {

namespace fs = std::filesystem;

bool exists(const std::string& path) {
  std::error_code ec;
  return !path.empty() && fs::exists(path, ec);
}

/// Seconds of `window` as [begin, end) after `origin` (same unit as origin: seconds).
struct SecondsRange {
  double begin = -std::numeric_limits<double>::infinity();
  double end = std::numeric_limits<double>::infinity();
  bool contains(double t) const { return t >= begin && t < end; }
};

SecondsRange range_after(double origin, const InputWindow& w) {
  SecondsRange r;
  const double start = w.start_s.value_or(0.0);
  if (w.start_s) r.begin = origin + start;
  if (w.duration_s) r.end = origin + start + *w.duration_s;
  return r;
}

/// Frames of a folder, each file read when asked for.
class FolderFrames : public FrameSource {
 public:
  FolderFrames(const io::Sequence& seq, std::vector<std::size_t> files)
      : seq_(seq), files_(std::move(files)) {}
  std::size_t size() const override { return files_.size(); }
  PointCloud<float> load(std::size_t i) const override {
    try {
      return seq_.load_frame<PointCloud<float>>(files_[i]).cloud;
    } catch (const std::exception& e) {
      fail(e.what());
      return {};
    }
  }

 private:
  const io::Sequence& seq_;
  std::vector<std::size_t> files_;
};

class FolderInput : public LidarInput {
 public:
  FolderInput(const std::string& path, const InputWindow& window) : seq_(path) {
    const SecondsRange r = range_after(seq_.frame(0).timestamp, window);
    for (std::size_t i = 0; i < seq_.size(); ++i)
      if (r.contains(seq_.frame(i).timestamp)) selected_.push_back(i);
    if (selected_.empty())
      throw io::IoError(path, "", "no frame inside the --start / --duration window");
    name_ = seq_.name();
  }

  std::string source() const override { return seq_.path().string(); }

  std::string name_when_repeated() const override {
    const fs::path p = seq_.path().lexically_normal();
    const fs::path parent = (p.filename().empty() ? p.parent_path() : p).parent_path().filename();
    return parent.empty() ? name_ : parent.string() + "/" + name_;
  }

  void visit(std::size_t first, std::size_t count, const FrameVisitor& fn) const override {
    for (std::size_t k = first, done = 0; k < selected_.size() && done < count; ++k, ++done) {
      auto frame = seq_.load_frame<PointCloud<float>>(selected_[k]);
      if (!fn(std::move(frame.cloud), frame.timestamp)) return;
    }
  }

  std::vector<double> frame_times() const override {
    std::vector<double> t;
    for (const std::size_t i : selected_) t.push_back(seq_.frame(i).timestamp);
    return t;
  }

  StreamedFrames stream(std::size_t first, std::size_t count) const override {
    StreamedFrames out;
    std::vector<std::size_t> files;
    for (std::size_t k = first; k < selected_.size() && files.size() < count; ++k) {
      files.push_back(selected_[k]);
      out.times.push_back(seq_.frame(selected_[k]).timestamp);
    }
    out.frames = std::make_unique<FolderFrames>(seq_, std::move(files));
    return out;
  }

  double period() const override { return odometry::frame_period(frame_times()); }

  double span_s() const override {
    return seq_.frame(selected_.back()).timestamp - seq_.frame(selected_.front()).timestamp;
  }

  /// The rate or unit the reader assumed (io::Sequence::notes).
  std::vector<std::string> warnings() const override { return seq_.notes(); }

 private:
  io::Sequence seq_;
  std::vector<std::size_t> selected_;
};

/// One recording, opened once for every LiDAR that reads from it.
struct Recording {
  std::string path;
  std::unique_ptr<bags::MessageSource> source;

  /// Receive time of the recording's first message (ns), 0 when it has none.
  std::int64_t first_message_ns() const {
    std::int64_t first = std::numeric_limits<std::int64_t>::max();
    for (const auto& t : source->topics())
      if (t.message_count > 0) first = std::min(first, t.first_time_ns);
    return first == std::numeric_limits<std::int64_t>::max() ? 0 : first;
  }
};

bags::TimeWindow receive_window(const Recording& rec, const InputWindow& w) {
  bags::TimeWindow out;
  const double origin = static_cast<double>(rec.first_message_ns());
  if (w.start_s) out.begin_ns = static_cast<std::int64_t>(origin + *w.start_s * 1e9);
  if (w.duration_s)
    out.end_ns =
        static_cast<std::int64_t>(origin + (w.start_s.value_or(0.0) + *w.duration_s) * 1e9);
  return out;
}

/// The topic a spec names, or the recording's only point-cloud topic when it names none.
std::string topic_of(const LidarSpec& spec, const Recording& rec, const std::string& command) {
  if (!spec.topic.empty()) return spec.topic;
  const auto clouds = bags::cloud_topics(*rec.source);
  if (clouds.size() == 1) return clouds.front().name;
  throw UsageError(command + ": '" + spec.text + "': name the LiDAR's topic as " + spec.path +
                   ":TOPIC; its point-cloud topics: " + bags::describe_cloud_topics(*rec.source));
}

class TopicInput : public LidarInput {
 public:
  TopicInput(std::shared_ptr<Recording> rec, const std::string& topic, const InputOptions& options)
      : rec_(std::move(rec)),
        topic_(*rec_->source, topic, rec_->path,
               options.frame_time == FrameTimeChoice::receive_time ? bags::FrameTime::receive_time
                                                                   : bags::FrameTime::header_stamp),
        window_(receive_window(*rec_, options.window)) {
    bags::TopicFrame first;
    auto frames = topic_.frames(window_);
    if (!frames.next(first))
      throw io::IoError(rec_->path, "",
                        "topic '" + topic + "' has no message" +
                            (options.window.start_s || options.window.duration_s
                                 ? " inside the --start / --duration window"
                                 : ""));
    const std::string& frame_id = first.message.header.frame_id;
    name_ = frame_id.empty() ? topic : frame_id;
  }

  std::string source() const override { return rec_->path + ":" + topic_.info().name; }
  std::string name_when_repeated() const override { return topic_.info().name; }

  void visit(std::size_t first, std::size_t count, const FrameVisitor& fn) const override {
    auto frames = topic_.frames(window_);
    bags::TopicFrame f;
    double previous = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; (k < first || k - first < count) && frames.next(f); ++k) {
      if (!(f.timestamp > previous))
        throw io::IoError(source(), "",
                          "frame " + std::to_string(k) + "'s time " + std::to_string(f.timestamp) +
                              " s does not come after the previous frame's " +
                              std::to_string(previous) +
                              " s (a driver that leaves header.stamp unset? try --frame-time "
                              "receive)");
      previous = f.timestamp;
      if (k < first) continue;
      if (!fn(io::to_cloud<PointCloud<float>>(f.message.cloud), f.timestamp)) return;
    }
  }

  double period() const override {
    const auto& t = topic_.info();
    if (t.message_count < 2) return 0.0;
    return static_cast<double>(t.last_time_ns - t.first_time_ns) * 1e-9 /
           static_cast<double>(t.message_count - 1);
  }

  double span_s() const override {
    const auto& t = topic_.info();
    return static_cast<double>(t.last_time_ns - t.first_time_ns) * 1e-9;
  }

  std::vector<std::string> warnings() const override { return rec_->source->warnings(); }

 private:
  std::shared_ptr<Recording> rec_;
  bags::CloudTopic topic_;
  bags::TimeWindow window_;
};

std::unique_ptr<LidarInput> open_one(const LidarSpec& spec, const InputOptions& options,
                                     std::map<std::string, std::shared_ptr<Recording>>& recordings,
                                     const std::string& command) {
  const bool recording = !spec.topic.empty() || bags::is_recording_path(spec.path);
  if (!recording) return std::make_unique<FolderInput>(spec.path, options.window);
  auto& rec = recordings[fs::weakly_canonical(spec.path).string()];
  if (!rec)
    rec = std::make_shared<Recording>(Recording{spec.path, bags::open_recording(spec.path)});
  return std::make_unique<TopicInput>(rec, topic_of(spec, *rec, command), options);
}

/// Default names that repeat take their name_when_repeated().
void disambiguate(std::vector<std::unique_ptr<LidarInput>>& inputs,
                  const std::vector<LidarSpec>& specs) {
  std::map<std::string, int> seen;
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (specs[i].name.empty()) ++seen[inputs[i]->name()];
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (specs[i].name.empty() && seen[inputs[i]->name()] >= 2)
      inputs[i]->set_name(inputs[i]->name_when_repeated());
}

void require_unique_names(const std::vector<std::unique_ptr<LidarInput>>& inputs,
                          const std::string& command) {
  std::set<std::string> names;
  for (const auto& in : inputs)
    if (!names.insert(in->name()).second)
      throw UsageError(command + ": two LiDARs are named '" + in->name() + "' (" + in->source() +
                       "); name them explicitly: PATH=NAME");
}

double non_negative(double v, const char* name, const std::string& command) {
  if (!(v >= 0.0 && std::isfinite(v)))
    throw UsageError(command + ": option '--" + name + "' must be a number >= 0");
  return v;
}

}  // namespace

StreamedFrames LidarInput::stream(std::size_t first, std::size_t count) const {
  auto spool = std::make_unique<SpooledFrames>(source());
  StreamedFrames out;
  visit(first, count, [&](PointCloud<float>&& cloud, double time) {
    spool->append(cloud);
    out.times.push_back(time);
    return true;
  });
  out.frames = std::move(spool);
  return out;
}

void add_frame_time_option(CLI::App& app, InputArgs& args) {
  app.add_option("--frame-time", args.frame_time,
                 "recordings: a frame's time is its header.stamp (header, default) or the time the "
                 "recorder received it (receive)")
      ->check(CLI::IsMember({"header", "receive"}));
}

void add_input_options(CLI::App& app, InputArgs& args) {
  args.start = app.add_option("--start", args.start_s,
                              "use the frames from S seconds after the recording's first message")
                   ->type_name("S");
  args.duration =
      app.add_option("--duration", args.duration_s, "use D seconds of frames (from --start)")
          ->type_name("D");
  add_frame_time_option(app, args);
}

InputOptions input_options(std::optional<double> start_s, std::optional<double> duration_s,
                           const std::string& frame_time, const std::string& command) {
  InputOptions o;
  if (start_s) o.window.start_s = non_negative(*start_s, "start", command);
  if (duration_s) {
    o.window.duration_s = non_negative(*duration_s, "duration", command);
    if (*o.window.duration_s <= 0.0)
      throw UsageError(command + ": option '--duration' must be more than 0 seconds");
  }
  if (frame_time != "header" && frame_time != "receive")
    throw UsageError(command + ": option '--frame-time' must be header or receive");
  o.frame_time =
      frame_time == "receive" ? FrameTimeChoice::receive_time : FrameTimeChoice::header_stamp;
  return o;
}

InputOptions input_options(const InputArgs& args, const std::string& command) {
  const auto given = [](const CLI::Option* o, double v) {
    return o && o->count() > 0 ? std::optional<double>(v) : std::nullopt;
  };
  return input_options(given(args.start, args.start_s), given(args.duration, args.duration_s),
                       args.frame_time, command);
}

void print_input_warnings(const std::vector<std::unique_ptr<LidarInput>>& inputs,
                          const std::string& command) {
  std::set<std::string> printed;
  for (const auto& in : inputs)
    for (const std::string& w : in->warnings())
      if (printed.insert(w).second)
        std::fprintf(stderr, "ulc %s: warning: %s\n", command.c_str(), w.c_str());
}

LidarSpec parse_lidar_spec(const std::string& text, const std::string& command,
                           const std::string& option) {
  LidarSpec spec;
  spec.text = text;
  std::string rest = text;
  const auto eq = rest.rfind('=');
  if (eq != std::string::npos && !exists(rest) && rest.find('/', eq) == std::string::npos) {
    spec.name = rest.substr(eq + 1);
    rest = rest.substr(0, eq);
    if (spec.name.empty())
      throw UsageError(command + ": option '--" + option + "': '" + text +
                       "' has an empty name after '='");
  }
  if (exists(rest) || rest.find(':') == std::string::npos) {
    spec.path = rest;
    return spec;
  }
  // FILE:TOPIC - the topic follows the last ':' whose left side exists.
  for (auto colon = rest.rfind(':'); colon != std::string::npos && colon > 0;
       colon = rest.rfind(':', colon - 1)) {
    if (!exists(rest.substr(0, colon))) continue;
    spec.path = rest.substr(0, colon);
    spec.topic = rest.substr(colon + 1);
    if (spec.topic.empty())
      throw UsageError(command + ": option '--" + option + "': '" + text + "' has an empty topic");
    return spec;
  }
  spec.path = rest;  // does not exist: the reader names it
  return spec;
}

std::vector<std::unique_ptr<LidarInput>> open_lidar_inputs(const std::vector<LidarSpec>& specs,
                                                           const InputOptions& options,
                                                           const std::string& command) {
  std::map<std::string, std::shared_ptr<Recording>> recordings;
  std::vector<std::unique_ptr<LidarInput>> inputs;
  for (const LidarSpec& spec : specs)
    inputs.push_back(open_one(spec, options, recordings, command));
  disambiguate(inputs, specs);
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (!specs[i].name.empty()) inputs[i]->set_name(specs[i].name);
  require_unique_names(inputs, command);
  return inputs;
}

}  // namespace ulc::app
