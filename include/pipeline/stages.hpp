// The stages of the calibration pipeline and the text form users type ("terra,jeep").
//
// Conventions this header owns:
//   - Stages always run in pipeline order: terra -> jeep -> hots (docs/design.md, "The house").
//     A stage list names each stage at most once, in that order; parse_stages says why a list
//     is not usable instead of reordering it silently.
//   - Nothing here throws (algorithm-header rules).
#pragma once

#include <string>
#include <vector>

namespace ulc {

enum class Stage { terra, jeep, hots };

inline const char* to_string(Stage s) {
  switch (s) {
    case Stage::terra:
      return "terra";
    case Stage::jeep:
      return "jeep";
    default:
      return "hots";
  }
}

inline bool has_stage(const std::vector<Stage>& stages, Stage s) {
  for (const Stage x : stages)
    if (x == s) return true;
  return false;
}

/// "terra,jeep" for {terra, jeep}.
inline std::string stages_to_string(const std::vector<Stage>& stages) {
  std::string out;
  for (const Stage s : stages) out += (out.empty() ? "" : ",") + std::string(to_string(s));
  return out;
}

/// Checks a stage list: not empty, each stage once, pipeline order. Empty string when usable.
inline std::string check_stages(const std::vector<Stage>& stages) {
  if (stages.empty()) return "no stage to run";
  for (std::size_t i = 1; i < stages.size(); ++i) {
    if (stages[i] == stages[i - 1])
      return std::string("stage '") + to_string(stages[i]) + "' twice";
    if (static_cast<int>(stages[i]) < static_cast<int>(stages[i - 1]))
      return std::string("stages run in the order terra, jeep, hots: '") + to_string(stages[i]) +
             "' cannot follow '" + to_string(stages[i - 1]) + "'";
  }
  return {};
}

struct ParsedStages {
  std::vector<Stage> stages;
  std::string error;  ///< empty when the text was usable
  bool ok() const { return error.empty(); }
};

/// Parses a comma-separated list such as "terra,jeep" (no spaces, names in lower case).
inline ParsedStages parse_stages(const std::string& text) {
  ParsedStages out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::size_t end = comma == std::string::npos ? text.size() : comma;
    const std::string name = text.substr(start, end - start);
    if (name == "terra") {
      out.stages.push_back(Stage::terra);
    } else if (name == "jeep") {
      out.stages.push_back(Stage::jeep);
    } else if (name == "hots") {
      out.stages.push_back(Stage::hots);
    } else {
      out.error = name.empty() ? "empty stage name in '" + text + "'"
                               : "unknown stage '" + name + "' (known: terra, jeep, hots)";
      return out;
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  out.error = check_stages(out.stages);
  return out;
}

}  // namespace ulc
