// The calibration result file of docs/design.md ("Result file"): one entry per target LiDAR inside
// "results", each with the transform in four spellings (matrix, translation, quaternion wxyz,
// roll/pitch/yaw in degrees with R = Rz(yaw) Ry(pitch) Rx(roll)), the clock offset, a 6x6
// covariance, per-stage statistics and timings. A failed calibration still has its entry, with
// success false, a status word and a human reason.
//
// Rig additions (additive: a reader that ignores unknown keys keeps working):
//   - an entry calibrated through another LiDAR v (pipeline/rig.hpp) has "via": "<v>" and
//     "direct": {"status", "reason"} of the failed direct attempt; its T_base_target is the
//     chain T_base_v * T_v_target, its stages are the v -> target calibration's. Entries
//     calibrated directly have neither key.
//   - a top-level "cycles" array next to "results", written when there are cycles:
//     {"lidars": [base, i, j], "status", "reason", "rotation_deg", "translation_m"}, the closure
//     error of T_base_i * T_i_j * T_base_j^-1 (null when the i -> j calibration failed).
//
// Observability (pipeline/observability_verdict.hpp; additive, older files read as "not
// judged"): "observability": {"problem": "hots" | "jeep", "weakest_share"} (null when no
// problem was judged) and "unobservable": [{"vector": [t; S phi], "share", "words"}, ...], the
// directions the final problem leaves free (status "degenerate"), empty otherwise.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "ulc/core/angles.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/observability_types.hpp"
#include "ulc/io/json_file.hpp"

namespace ulc::io {

struct PairResult {
  std::string base;
  std::string target;
  bool success = false;
  std::string status = "not_run";
  std::string reason;
  Eigen::Isometry3d T_base_target = Eigen::Isometry3d::Identity();
  std::optional<double> time_offset_s;  ///< t_base_clock = t_target_clock + time_offset_s
  std::optional<Eigen::Matrix<double, 6, 6>> covariance_6x6;  ///< tangent order [rho; phi]
  Json stages = Json::object();    ///< {"terra": {...}, "jeep": {...}, "hots": {...}}
  Json timing_s = Json::object();  ///< seconds per stage and "total"
  std::string via;                 ///< the LiDAR it was calibrated through; empty: direct
  std::string direct_status;       ///< when routed: the direct attempt's status word
  std::string direct_reason;       ///< when routed: why the direct attempt failed
  /// What the data cannot vouch for (pipeline/vouch.hpp): "clock" {source, note, speed, lag,
  /// ...} when a translation was estimated, "point_times" {"base": {...}, "target": {...}}.
  /// Null: not written.
  Json clock;
  Json point_times;
  /// Observability: the problem judged ("hots", "jeep"; empty: none), its weakest share, and
  /// the directions it leaves free (ulc/core/observability.hpp).
  std::string observability_problem;
  std::optional<double> weakest_share;
  std::vector<ulc::UnobservableDirection> unobservable;
};

/// The cycle base -> i -> j -> base: how far T_base_i * T_i_j * T_base_j^-1 is from identity.
struct CycleResult {
  std::vector<std::string> lidars;     ///< {base, i, j}
  std::string status = "not_run";      ///< of the i -> j calibration
  std::string reason;                  ///< of the i -> j calibration
  std::optional<double> rotation_deg;  ///< null unless the i -> j calibration succeeded
  std::optional<double> translation_m;
};

/// Everything a result file holds.
struct ResultDocument {
  std::vector<PairResult> results;
  std::vector<CycleResult> cycles;
};

/// {"problem", "weakest_share"}, or null when no problem was judged.
inline Json observability_to_json(const PairResult& r) {
  if (r.observability_problem.empty() || !r.weakest_share) return Json();
  Json j = Json::object();
  j["problem"] = r.observability_problem;
  j["weakest_share"] = *r.weakest_share;
  return j;
}

inline Json unobservable_to_json(const std::vector<ulc::UnobservableDirection>& free) {
  Json list = Json::array();
  for (const auto& d : free) {
    Json j = Json::object();
    j["vector"] = vector_to_json(d.vector);
    j["share"] = d.share;
    j["words"] = d.words;
    list.push_back(std::move(j));
  }
  return list;
}

/// "observability" and "unobservable" of an entry into r (absent keys: not judged).
inline void observability_from_json(const Json& e, const std::string& file,
                                    const std::string& where, PairResult& r) {
  if (const Json* o = find_member(e, "observability"); o && o->is_object()) {
    if (const Json* p = find_member(*o, "problem"); p && p->is_string())
      r.observability_problem = p->get<std::string>();
    if (const Json* w = find_member(*o, "weakest_share"); w && w->is_number())
      r.weakest_share = json_to_number(*w, file, where + ".observability.weakest_share");
  }
  const Json* list = find_member(e, "unobservable");
  if (!list) return;
  if (!list->is_array()) throw IoError(file, where + ".unobservable", "expected an array");
  for (std::size_t k = 0; k < list->size(); ++k) {
    const std::string at = where + ".unobservable[" + std::to_string(k) + "]";
    const Json& d = (*list)[k];
    const Json* v = find_member(d, "vector");
    if (!v || !v->is_array() || v->size() != 6)
      throw IoError(file, at + ".vector", "expected an array of 6 numbers");
    ulc::UnobservableDirection u;
    for (std::size_t i = 0; i < 6; ++i)
      u.vector[static_cast<Eigen::Index>(i)] =
          json_to_number((*v)[i], file, at + ".vector[" + std::to_string(i) + "]");
    if (const Json* s = find_member(d, "share"); s && s->is_number())
      u.share = json_to_number(*s, file, at + ".share");
    if (const Json* w = find_member(d, "words"); w && w->is_string())
      u.words = w->get<std::string>();
    r.unobservable.push_back(std::move(u));
  }
}

inline Json to_json(const PairResult& r) {
  Json e = Json::object();
  e["base"] = r.base;
  e["target"] = r.target;
  e["success"] = r.success;
  e["status"] = r.status;
  e["reason"] = r.reason;
  e["T_base_target"] = matrix_to_json(r.T_base_target.matrix());
  e["translation_m"] = vector_to_json(r.T_base_target.translation());
  const Eigen::Quaterniond q(r.T_base_target.linear());
  e["rotation_quat_wxyz"] = vector_to_json(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
  e["rpy_deg"] = vector_to_json(ulc::rpy_from_rotation(r.T_base_target.linear()) * kDegPerRad);
  e["time_offset_s"] = r.time_offset_s ? Json(*r.time_offset_s) : Json();
  e["covariance_6x6"] = r.covariance_6x6 ? matrix_to_json(*r.covariance_6x6) : Json();
  if (!r.clock.is_null()) e["clock"] = r.clock;
  if (!r.point_times.is_null()) e["point_times"] = r.point_times;
  e["observability"] = observability_to_json(r);
  e["unobservable"] = unobservable_to_json(r.unobservable);
  e["stages"] = r.stages;
  e["timing_s"] = r.timing_s;
  if (!r.via.empty()) {
    e["via"] = r.via;
    Json direct = Json::object();
    direct["status"] = r.direct_status;
    direct["reason"] = r.direct_reason;
    e["direct"] = std::move(direct);
  }
  return e;
}

inline Json to_json(const CycleResult& c) {
  Json e = Json::object();
  Json lidars = Json::array();
  for (const auto& name : c.lidars) lidars.push_back(name);
  e["lidars"] = std::move(lidars);
  e["status"] = c.status;
  e["reason"] = c.reason;
  e["rotation_deg"] = c.rotation_deg ? Json(*c.rotation_deg) : Json();
  e["translation_m"] = c.translation_m ? Json(*c.translation_m) : Json();
  return e;
}

/// {"results": [...]} and, when there are cycles, "cycles": [...].
inline Json results_to_json(const std::vector<PairResult>& results,
                            const std::vector<CycleResult>& cycles = {}) {
  Json list = Json::array();
  for (const auto& r : results) list.push_back(to_json(r));
  Json doc = Json::object();
  doc["results"] = std::move(list);
  if (!cycles.empty()) {
    Json c = Json::array();
    for (const auto& cycle : cycles) c.push_back(to_json(cycle));
    doc["cycles"] = std::move(c);
  }
  return doc;
}

/// Reads the fields a consumer needs (the matrix is authoritative over the other spellings).
inline std::vector<PairResult> results_from_json(const Json& doc, const std::string& file) {
  const Json* list = find_member(doc, "results");
  if (!list || !list->is_array())
    throw IoError(file, "results", "missing array \"results\" (is this a ulc result file?)");
  std::vector<PairResult> out;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const Json& e = (*list)[i];
    const std::string where = "results[" + std::to_string(i) + "]";
    if (!e.is_object()) throw IoError(file, where, "expected an object");
    PairResult r;
    const Json* base = find_member(e, "base");
    const Json* target = find_member(e, "target");
    if (!base || !base->is_string() || !target || !target->is_string())
      throw IoError(file, where, "needs string \"base\" and \"target\"");
    r.base = base->get<std::string>();
    r.target = target->get<std::string>();
    if (const Json* s = find_member(e, "success"); s && s->is_boolean()) r.success = s->get<bool>();
    if (const Json* s = find_member(e, "status"); s && s->is_string())
      r.status = s->get<std::string>();
    if (const Json* s = find_member(e, "reason"); s && s->is_string())
      r.reason = s->get<std::string>();
    const Json* t = find_member(e, "T_base_target");
    if (!t) throw IoError(file, where, "missing T_base_target");
    r.T_base_target = json_to_isometry(*t, file, where + ".T_base_target");
    if (const Json* dt = find_member(e, "time_offset_s"); dt && dt->is_number())
      r.time_offset_s = json_to_number(*dt, file, where + ".time_offset_s");
    if (const Json* c = find_member(e, "covariance_6x6"); c && c->is_array())
      r.covariance_6x6 = json_to_matrix<6, 6>(*c, file, where + ".covariance_6x6");
    observability_from_json(e, file, where, r);
    if (const Json* s = find_member(e, "stages"); s && s->is_object()) r.stages = *s;
    if (const Json* s = find_member(e, "timing_s"); s && s->is_object()) r.timing_s = *s;
    if (const Json* c = find_member(e, "clock"); c && c->is_object()) r.clock = *c;
    if (const Json* p = find_member(e, "point_times"); p && p->is_object()) r.point_times = *p;
    if (const Json* v = find_member(e, "via"); v && v->is_string()) r.via = v->get<std::string>();
    if (const Json* d = find_member(e, "direct"); d && d->is_object()) {
      if (const Json* s = find_member(*d, "status"); s && s->is_string())
        r.direct_status = s->get<std::string>();
      if (const Json* s = find_member(*d, "reason"); s && s->is_string())
        r.direct_reason = s->get<std::string>();
    }
    out.push_back(std::move(r));
  }
  return out;
}

/// The top-level "cycles" (empty when the file has none).
inline std::vector<CycleResult> cycles_from_json(const Json& doc, const std::string& file) {
  std::vector<CycleResult> out;
  const Json* list = find_member(doc, "cycles");
  if (!list) return out;
  if (!list->is_array()) throw IoError(file, "cycles", "expected an array");
  for (std::size_t i = 0; i < list->size(); ++i) {
    const Json& e = (*list)[i];
    const std::string where = "cycles[" + std::to_string(i) + "]";
    const Json* lidars = find_member(e, "lidars");
    if (!lidars || !lidars->is_array())
      throw IoError(file, where, "needs an array \"lidars\" of names");
    CycleResult c;
    for (std::size_t k = 0; k < lidars->size(); ++k) {
      if (!(*lidars)[k].is_string()) throw IoError(file, where + ".lidars", "expected names");
      c.lidars.push_back((*lidars)[k].get<std::string>());
    }
    if (const Json* s = find_member(e, "status"); s && s->is_string())
      c.status = s->get<std::string>();
    if (const Json* s = find_member(e, "reason"); s && s->is_string())
      c.reason = s->get<std::string>();
    if (const Json* x = find_member(e, "rotation_deg"); x && x->is_number())
      c.rotation_deg = json_to_number(*x, file, where + ".rotation_deg");
    if (const Json* x = find_member(e, "translation_m"); x && x->is_number())
      c.translation_m = json_to_number(*x, file, where + ".translation_m");
    out.push_back(std::move(c));
  }
  return out;
}

inline std::vector<PairResult> read_result_file(const std::string& path) {
  return results_from_json(read_json_file(path), path);
}

/// The results and the cycles of a result file.
inline ResultDocument read_result_document(const std::string& path) {
  const Json doc = read_json_file(path);
  return {results_from_json(doc, path), cycles_from_json(doc, path)};
}

inline void write_result_file(const std::string& path, const std::vector<PairResult>& results,
                              const std::vector<CycleResult>& cycles = {}) {
  write_json_file(path, results_to_json(results, cycles));
}

}  // namespace ulc::io
