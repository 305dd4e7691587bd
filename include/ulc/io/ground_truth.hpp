// ground_truth.json of a dataset folder (docs/design.md): per LiDAR its model and T_vehicle_lidar,
// per pair T_base_target and the clock offset (t_base_clock = t_target_clock + time_offset_s).
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "ulc/io/json_file.hpp"

namespace ulc::io {

inline constexpr const char* kTimeOffsetConvention =
    "t_base_clock = t_target_clock + time_offset_s";

struct LidarTruth {
  std::string name;
  std::string model;
  Eigen::Isometry3d T_vehicle_lidar = Eigen::Isometry3d::Identity();
};

struct PairTruth {
  std::string base;
  std::string target;
  Eigen::Isometry3d T_base_target = Eigen::Isometry3d::Identity();
  std::optional<double> time_offset_s;  ///< absent or null when unknown
};

struct GroundTruth {
  std::vector<LidarTruth> lidars;
  std::vector<PairTruth> pairs;

  const PairTruth* find_pair(const std::string& base, const std::string& target) const {
    for (const auto& p : pairs)
      if (p.base == base && p.target == target) return &p;
    return nullptr;
  }
  const LidarTruth* find_lidar(const std::string& name) const {
    for (const auto& l : lidars)
      if (l.name == name) return &l;
    return nullptr;
  }
};

inline Json to_json(const GroundTruth& gt) {
  Json doc = Json::object();
  Json lidars = Json::object();
  for (const auto& l : gt.lidars) {
    Json entry = Json::object();
    entry["model"] = l.model;
    entry["T_vehicle_lidar"] = matrix_to_json(l.T_vehicle_lidar.matrix());
    lidars[l.name] = std::move(entry);
  }
  doc["lidars"] = std::move(lidars);
  Json pairs = Json::array();
  for (const auto& p : gt.pairs) {
    Json entry = Json::object();
    entry["base"] = p.base;
    entry["target"] = p.target;
    entry["T_base_target"] = matrix_to_json(p.T_base_target.matrix());
    entry["time_offset_s"] = p.time_offset_s ? Json(*p.time_offset_s) : Json();
    pairs.push_back(std::move(entry));
  }
  doc["pairs"] = std::move(pairs);
  doc["time_offset_convention"] = kTimeOffsetConvention;
  return doc;
}

inline GroundTruth ground_truth_from_json(const Json& doc, const std::string& file) {
  if (!doc.is_object()) throw IoError(file, "", "expected a JSON object");
  GroundTruth gt;
  if (const Json* lidars = find_member(doc, "lidars")) {
    if (!lidars->is_object()) throw IoError(file, "lidars", "expected an object");
    for (auto kv = lidars->begin(); kv != lidars->end(); ++kv) {
      LidarTruth l;
      l.name = kv.key();
      const std::string where = "lidars." + kv.key();
      if (const Json* m = find_member(kv.value(), "model"); m && m->is_string())
        l.model = m->get<std::string>();
      const Json* t = find_member(kv.value(), "T_vehicle_lidar");
      if (!t) throw IoError(file, where, "missing T_vehicle_lidar");
      l.T_vehicle_lidar = json_to_isometry(*t, file, where + ".T_vehicle_lidar");
      gt.lidars.push_back(std::move(l));
    }
  }
  const Json* pairs = find_member(doc, "pairs");
  if (!pairs || !pairs->is_array()) throw IoError(file, "pairs", "missing array \"pairs\"");
  for (std::size_t i = 0; i < pairs->size(); ++i) {
    const Json& e = (*pairs)[i];
    const std::string where = "pairs[" + std::to_string(i) + "]";
    const Json* base = find_member(e, "base");
    const Json* target = find_member(e, "target");
    const Json* t = find_member(e, "T_base_target");
    if (!base || !base->is_string() || !target || !target->is_string() || !t)
      throw IoError(file, where, "needs string \"base\", string \"target\" and \"T_base_target\"");
    PairTruth p;
    p.base = base->get<std::string>();
    p.target = target->get<std::string>();
    p.T_base_target = json_to_isometry(*t, file, where + ".T_base_target");
    if (const Json* dt = find_member(e, "time_offset_s"); dt && dt->is_number())
      p.time_offset_s = json_to_number(*dt, file, where + ".time_offset_s");
    gt.pairs.push_back(std::move(p));
  }
  return gt;
}

inline GroundTruth read_ground_truth(const std::string& path) {
  return ground_truth_from_json(read_json_file(path), path);
}

inline void write_ground_truth(const std::string& path, const GroundTruth& gt) {
  write_json_file(path, to_json(gt));
}

}  // namespace ulc::io
