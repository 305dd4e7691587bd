// `ulc evaluate`: a result file against a dataset's ground truth, with the paper's metrics.
// A rig's result file also carries routes ("via") and cycle closures: they are shown as written
// (a closure needs no ground truth) and do not change the exit code.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "command_line.hpp"
#include "commands.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/result_file.hpp"

namespace ulc::app {
namespace {

struct PairEvaluation {
  std::string base, target;
  bool found_truth = false;
  bool calibrated = false;
  ulc::PoseError error{};
  std::optional<double> time_offset_error_s;
  bool success = false;
};

PairEvaluation evaluate_pair(const io::PairResult& r, const io::GroundTruth& gt) {
  PairEvaluation ev;
  ev.base = r.base;
  ev.target = r.target;
  ev.calibrated = r.success;
  Eigen::Isometry3d truth;
  std::optional<double> truth_offset;
  if (const auto* p = gt.find_pair(r.base, r.target)) {
    truth = p->T_base_target;
    truth_offset = p->time_offset_s;
  } else if (const auto* q = gt.find_pair(r.target, r.base)) {
    truth = q->T_base_target.inverse();
    if (q->time_offset_s) truth_offset = -*q->time_offset_s;
  } else if (const auto* a = gt.find_lidar(r.base), *b = gt.find_lidar(r.target); a && b) {
    truth = a->T_vehicle_lidar.inverse() * b->T_vehicle_lidar;
  } else {
    return ev;
  }
  ev.found_truth = true;
  ev.error = ulc::pose_error(truth, r.T_base_target);
  if (truth_offset && r.time_offset_s) ev.time_offset_error_s = *r.time_offset_s - *truth_offset;
  ev.success = r.success && ulc::is_calibration_success(ev.error);
  return ev;
}

}  // namespace

int run_evaluate(int argc, char** argv) {
  CLI::App app(
      "Compares a result file with the ground truth: e_rot (deg), e_trans (m), time-offset "
      "error, success.",
      "ulc evaluate");
  std::string result_path, truth_path;
  bool json = false;
  app.add_option("--result", result_path, "result file written by `ulc calibrate --output`")
      ->type_name("FILE")
      ->required();
  app.add_option("--ground-truth", truth_path, "the dataset's ground_truth.json")
      ->type_name("FILE")
      ->required();
  app.add_flag("--json", json, "print JSON instead of a table");
  if (parse_command_line(app, "evaluate", argc, argv)) return kExitOk;
  const io::ResultDocument file = io::read_result_document(result_path);
  const std::vector<io::PairResult>& results = file.results;
  const auto gt = io::read_ground_truth(truth_path);

  io::Json pairs = io::Json::array();
  int failures = 0;
  for (const auto& r : results) {
    const PairEvaluation ev = evaluate_pair(r, gt);
    if (!ev.success) ++failures;
    io::Json e = io::Json::object();
    e["base"] = ev.base;
    e["target"] = ev.target;
    e["ground_truth_found"] = ev.found_truth;
    e["calibration_success_reported"] = ev.calibrated;
    e["e_rot_deg"] = ev.found_truth ? io::Json(ev.error.rotation_deg) : io::Json();
    e["e_trans_m"] = ev.found_truth ? io::Json(ev.error.translation_m) : io::Json();
    e["time_offset_error_s"] =
        ev.time_offset_error_s ? io::Json(*ev.time_offset_error_s) : io::Json();
    e["success"] = ev.success;
    if (!r.via.empty()) e["via"] = r.via;
    pairs.push_back(std::move(e));
  }
  io::Json cycles = io::Json::array();
  for (const auto& c : file.cycles) cycles.push_back(io::to_json(c));
  if (json) {
    io::Json doc = io::Json::object();
    doc["pairs"] = std::move(pairs);
    if (!file.cycles.empty()) doc["cycles"] = std::move(cycles);
    doc["success_criterion"] = "e_rot < 1 deg and e_trans < 0.1 m";
    std::printf("%s\n", io::dump_json(doc).c_str());
  } else {
    std::printf("%-12s %-12s %10s %10s %12s  %s\n", "base", "target", "e_rot_deg", "e_trans_m",
                "dt_error_ms", "success");
    for (const auto& e : pairs) {
      auto num = [](const io::Json& j, double scale, const char* fmt) {
        char buf[32];
        if (!j.is_number()) return std::string("-");
        std::snprintf(buf, sizeof buf, fmt, j.get<double>() * scale);
        return std::string(buf);
      };
      const io::Json* via = io::find_member(e, "via");
      std::printf("%-12s %-12s %10s %10s %12s  %s%s%s\n", e.at("base").get<std::string>().c_str(),
                  e.at("target").get<std::string>().c_str(),
                  num(e.at("e_rot_deg"), 1, "%.4f").c_str(),
                  num(e.at("e_trans_m"), 1, "%.4f").c_str(),
                  num(e.at("time_offset_error_s"), 1000, "%.2f").c_str(),
                  !e.at("ground_truth_found").get<bool>() ? "no ground truth"
                  : e.at("success").get<bool>()           ? "yes"
                                                          : "no",
                  via ? " (via " : "", via ? (via->get<std::string>() + ")").c_str() : "");
    }
    std::printf("success: e_rot < 1 deg and e_trans < 0.1 m (and the calibration said ok)\n");
    for (const auto& c : file.cycles) {
      std::string names;
      for (const auto& n : c.lidars) names += n + " -> ";
      names += c.lidars.empty() ? "" : c.lidars.front();
      if (c.rotation_deg && c.translation_m)
        std::printf("cycle %s: closure %.4f deg %.4f m\n", names.c_str(), *c.rotation_deg,
                    *c.translation_m);
      else
        std::printf("cycle %s: not closed (%s)\n", names.c_str(), c.status.c_str());
    }
  }
  return failures == 0 && !results.empty() ? kExitOk : kExitFailed;
}

}  // namespace ulc::app
