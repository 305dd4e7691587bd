#include "drive_selection.hpp"

#include "progress.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::app {

Selection survey_drive(const LidarInput& base, const SelectionOptions& options, bool quiet) {
  DriveSurvey<float> survey(options, base.period());
  const std::vector<double> times = base.frame_times();
  Progress progress("survey", quiet);
  double first = 0.0, last = 0.0;
  if (!times.empty()) {  // random access: read only the frames the survey registers
    const StreamedFrames frames = base.stream(0, kAllFrames);
    for (std::size_t k = 0; k < times.size(); ++k) {
      if (survey.wants(times[k])) survey.add(frames.frames->load(k), times[k]);
      progress.update(k + 1, times.size());
    }
    if (const std::string why = frames.frames->error(); !why.empty())
      throw io::IoError(base.source(), "", "a frame could not be read: " + why);
    first = times.front();
    last = times.back();
  } else {
    bool any = false;
    base.visit(0, kAllFrames, [&](PointCloud<float>&& cloud, double time) {
      survey.add(cloud, time);
      if (!any) first = time;
      any = true;
      last = time;
      progress.update(0, 0);
      return true;
    });
  }
  Selection s = survey.select(first, last);
  s.seconds = progress.elapsed();
  return s;
}

io::Json selection_json(const Selection& s, double budget_s) {
  io::Json j = io::Json::object();
  j["applied"] = s.applied;
  j["budget_s"] = budget_s;
  j["drive_s"] = s.drive_s;
  j["start_s"] = s.start_s;
  j["end_s"] = s.end_s;
  j["why"] = s.why;
  j["seconds"] = s.seconds;
  io::Json windows = io::Json::array();
  for (const StretchScore& w : s.windows) {
    io::Json e = io::Json::object();
    e["start_s"] = w.start_s;
    e["end_s"] = w.end_s;
    const Vec3d deg = w.rotation_rad * (180.0 / 3.14159265358979323846);
    e["rotation_deg"] = {deg.x(), deg.y(), deg.z()};
    e["speed_change_mps"] = w.speed_change_mps;
    e["structure"] = w.structure;
    e["score"] = w.score;
    windows.push_back(std::move(e));
  }
  if (s.applied) j["chosen"] = s.chosen;
  j["windows"] = std::move(windows);
  return j;
}

}  // namespace ulc::app
