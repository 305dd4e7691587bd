// Uses the installed readers and writers of ULC's own files (COMPONENTS results): writes a result
// file and its YAML form and reads the result file back.
#include <cstdio>
#include <filesystem>

#include "ulc/io/result_file.hpp"
#include "ulc/io/result_yaml.hpp"

int main() {
  const auto file = std::filesystem::temp_directory_path() / "ulc_consumer_results.json";
  ulc::io::PairResult r;
  r.base = "top";
  r.target = "left";
  r.success = true;
  r.status = "ok";
  r.T_base_target.translation() = Eigen::Vector3d(0.5, -1.0, 0.25);
  ulc::io::write_result_file(file.string(), {r});
  const auto back = ulc::io::read_result_file(file.string());
  std::filesystem::remove(file);
  const bool ok = back.size() == 1 && back[0].target == "left" &&
                  back[0].T_base_target.isApprox(r.T_base_target) &&
                  ulc::io::results_to_yaml(back).find("target: \"left\"") != std::string::npos;
  std::printf("consumer_results: %s\n", ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
