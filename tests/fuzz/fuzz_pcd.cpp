// Fuzzes the PCD reader (ulc/io/pcd_read.hpp): header, then DATA ascii, binary or
// binary_compressed (LZF), on the input bytes as a whole file.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "ulc/io/pcd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    ulc::io::ReadStats stats;
    const ulc::io::DecodedCloud cloud = ulc::io::decode_pcd(data, size, "fuzz.pcd", &stats);
    ulc_fuzz::check_decoded(cloud);
    ulc_fuzz::fuzz_require(
        stats.points_read + stats.points_dropped_nonfinite == stats.points_in_file,
        "PCD: points read + dropped differ from the points in the file");
  } catch (const ulc::io::IoError&) {
    // A refused file: the expected outcome for most inputs.
  }
  return 0;
}
