// Fuzzes the frame-time parsers of a dataset folder (ulc/io/sequence.hpp): timestamps.txt (one
// time in seconds per line) and the times encoded in frame file names ("1645000000.123.pcd",
// Unix nanoseconds), here the input's first line taken as a file stem.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "ulc/io/sequence.hpp"

namespace {

void fuzz_timestamps_file(const std::uint8_t* data, std::size_t size) {
  const auto path = ulc_fuzz::input_file(data, size, "timestamps.txt");
  try {
    for (const double t : ulc::io::detail::read_timestamps_file(path))
      ulc_fuzz::fuzz_require(std::isfinite(t), "timestamps.txt: a non-finite time was accepted");
  } catch (const ulc::io::IoError&) {
    // A refused file: the expected outcome for most inputs.
  }
}

void fuzz_file_name(const std::uint8_t* data, std::size_t size) {
  const auto* text = reinterpret_cast<const char*>(data);
  std::string stem(text, std::find(text, text + size, '\n'));
  // A name, not a path: no folder separators, no NUL.
  std::replace(stem.begin(), stem.end(), '/', '_');
  std::replace(stem.begin(), stem.end(), '\0', '_');
  const double t = ulc::io::detail::time_from_file_name(stem + ".pcd");
  ulc_fuzz::fuzz_require(std::isnan(t) || std::isfinite(t),
                         "file name: a time that is neither finite nor NaN");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz_timestamps_file(data, size);
  fuzz_file_name(data, size);
  return 0;
}
