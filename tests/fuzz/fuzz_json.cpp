// Fuzzes ULC's JSON files: parse_json (nlohmann::json behind ulc/io/json_file.hpp, which must
// refuse bad input with an IoError only), then what reads a parsed document -- the result file
// (ulc/io/result_file.hpp, results and cycles), ground_truth.json (ulc/io/ground_truth.hpp) --
// and `ulc calibrate --initial` (apps/ulc/initial_extrinsic.hpp), both as six numbers on the
// command line and as a result file.
//
// A parsed document must survive a round trip through our layout: dump_json() parses back to the
// same text; and what the readers accept must write and read back the same.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "fuzz_support.hpp"
#include "initial_extrinsic.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/json_file.hpp"
#include "ulc/io/result_file.hpp"

namespace {

std::optional<ulc::io::Json> parse(const std::string& text) {
  try {
    return ulc::io::parse_json(text, "fuzz.json");
  } catch (const ulc::io::IoError&) {
    return std::nullopt;
  }
}

/// Writing what was read must give text that reads back the same (an IoError here escapes).
void check_round_trip(const ulc::io::Json& doc) {
  const std::string once = ulc::io::dump_json(doc);
  const std::string twice = ulc::io::dump_json(ulc::io::parse_json(once, "fuzz.json dumped"));
  ulc_fuzz::fuzz_require(once == twice, "JSON: dump -> parse -> dump changed the text");
}

void read_documents(const ulc::io::Json& doc) {
  try {
    const auto results = ulc::io::results_from_json(doc, "fuzz.json");
    const auto cycles = ulc::io::cycles_from_json(doc, "fuzz.json");
    // What was read writes and reads back the same.
    const ulc::io::Json again = ulc::io::parse_json(
        ulc::io::dump_json(ulc::io::results_to_json(results, cycles)), "fuzz.json written");
    const auto back = ulc::io::results_from_json(again, "fuzz.json written");
    ulc_fuzz::fuzz_require(back.size() == results.size(), "result file: entries lost on rewrite");
    for (std::size_t i = 0; i < back.size(); ++i)
      ulc_fuzz::fuzz_require(back[i].base == results[i].base &&
                                 back[i].target == results[i].target &&
                                 back[i].T_base_target.isApprox(results[i].T_base_target, 1e-9),
                             "result file: an entry changed on rewrite");
  } catch (const ulc::io::IoError&) {
  }
  try {
    (void)ulc::io::cycles_from_json(doc, "fuzz.json");
  } catch (const ulc::io::IoError&) {
  }
  try {
    (void)ulc::io::ground_truth_from_json(doc, "fuzz.json");
  } catch (const ulc::io::IoError&) {
  }
}

/// `--initial "x y z roll pitch yaw"` and `--initial result.json`.
void parse_initial(const std::uint8_t* data, std::size_t size, const std::string& text) {
  try {
    const Eigen::Isometry3d T = ulc::app::parse_initial_numbers(text);
    ulc_fuzz::fuzz_require(T.matrix().allFinite(), "--initial numbers: a non-finite transform");
  } catch (const ulc::app::UsageError&) {
  }
  const auto path = ulc_fuzz::input_file(data, size, "initial.json");
  try {
    const Eigen::Isometry3d T = ulc::app::parse_initial(path.string(), "base", "target");
    ulc_fuzz::fuzz_require(T.matrix().allFinite(), "--initial file: a non-finite transform");
  } catch (const ulc::io::IoError&) {
  } catch (const ulc::app::UsageError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (const auto doc = parse(text)) {
    check_round_trip(*doc);
    read_documents(*doc);
  }
  parse_initial(data, size, text);
  return 0;
}
