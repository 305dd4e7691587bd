# ulc::results: ULC's own files -- the result file, ground_truth.json and the YAML result
# (include/ulc/io/json_file.hpp, result_file.hpp, result_entry.hpp, ground_truth.hpp,
# result_yaml.hpp) and the simulator's dataset writer (include/ulc/sim/dataset_writer.hpp), which
# writes ground_truth.json. Header-only like the rest; they read and write JSON with Debian's
# nlohmann-json3-dev and YAML with libyaml-cpp-dev.
# Kept apart from ulc::ulc: a user who needs only the algorithms keeps its three dependencies.
find_package(nlohmann_json 3.10 REQUIRED)
find_package(yaml-cpp REQUIRED)

add_library(ulc_results INTERFACE)
add_library(ulc::results ALIAS ulc_results)
set_target_properties(ulc_results PROPERTIES EXPORT_NAME results)
target_link_libraries(ulc_results INTERFACE ulc::ulc nlohmann_json::nlohmann_json yaml-cpp)
