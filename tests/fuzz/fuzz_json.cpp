// Fuzzes ULC's JSON files: the parser (ulc/io/json.hpp), then what reads a parsed document -- the
// result file (ulc/io/result_file.hpp, results and cycles), ground_truth.json
// (ulc/io/ground_truth.hpp) -- and `ulc calibrate --initial` (apps/ulc/initial_extrinsic.hpp),
// both as six numbers on the command line and as a result file.
//
// A parsed document must survive a round trip: dump() parses back to the same text.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "fuzz_support.hpp"
#include "initial_extrinsic.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/json.hpp"
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
  const std::string once = doc.dump();
  const std::string twice = ulc::io::parse_json(once, "fuzz.json dumped").dump();
  ulc_fuzz::fuzz_require(once == twice, "JSON: dump -> parse -> dump changed the text");
}

void read_documents(const ulc::io::Json& doc) {
  try {
    (void)ulc::io::results_from_json(doc, "fuzz.json");
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
  } catch (const ulc::cli::UsageError&) {
  }
  const auto path = ulc_fuzz::input_file(data, size, "initial.json");
  try {
    const Eigen::Isometry3d T = ulc::app::parse_initial(path.string(), "base", "target");
    ulc_fuzz::fuzz_require(T.matrix().allFinite(), "--initial file: a non-finite transform");
  } catch (const ulc::io::IoError&) {
  } catch (const ulc::cli::UsageError&) {
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
