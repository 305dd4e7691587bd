// Fuzzes the frame-time parsers of a dataset folder (ulc/io/sequence.hpp, frame_times.hpp):
// timestamps.txt (one time per line, its unit then decided) and the times encoded in frame file
// names ("1645000000.123.pcd", "1645000000.5000000.pcd", Unix nanoseconds), here each line of
// the input taken as a file stem.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "ulc/io/sequence.hpp"

namespace {

void fuzz_timestamps_file(const std::uint8_t* data, std::size_t size) {
  const auto path = ulc_fuzz::input_file(data, size, "timestamps.txt");
  try {
    std::vector<double> times = ulc::io::detail::read_timestamps_file(path);
    for (const double t : times)
      ulc_fuzz::fuzz_require(std::isfinite(t), "timestamps.txt: a non-finite time was accepted");
    ulc::io::detail::require_increasing_lines(times, path);
    const double unit = ulc::io::frame_time_unit(times, path.string(), "frame times").seconds;
    ulc_fuzz::fuzz_require(unit > 0.0 && unit <= 1.0, "timestamps.txt: a unit beyond seconds");
  } catch (const ulc::io::IoError&) {
    // A refused file: the expected outcome for most inputs.
  }
}

void fuzz_file_names(const std::uint8_t* data, std::size_t size) {
  const auto* text = reinterpret_cast<const char*>(data);
  std::vector<std::filesystem::path> frames;
  for (const char* line = text; line < text + size && frames.size() < 64;) {
    const char* end = std::find(line, text + size, '\n');
    std::string stem(line, end);
    // A name, not a path: no folder separators, no NUL.
    std::replace(stem.begin(), stem.end(), '/', '_');
    std::replace(stem.begin(), stem.end(), '\0', '_');
    frames.emplace_back(stem + ".pcd");
    line = end + 1;
  }
  try {
    if (const auto times = ulc::io::times_from_file_names(frames))
      for (const double t : *times)
        ulc_fuzz::fuzz_require(std::isfinite(t), "file name: a time that is not finite");
  } catch (const ulc::io::IoError&) {
    // Ambiguous names: refused.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz_timestamps_file(data, size);
  fuzz_file_names(data, size);
  return 0;
}
