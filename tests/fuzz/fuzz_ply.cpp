// Fuzzes the PLY reader (ulc/io/ply_read.hpp): header, elements before `vertex` (lists
// included), then the vertices in ascii, binary_little_endian or binary_big_endian.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "ulc/io/ply.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    ulc::io::ReadStats stats;
    const ulc::io::DecodedCloud cloud = ulc::io::decode_ply(data, size, "fuzz.ply", &stats);
    ulc_fuzz::check_decoded(cloud);
    ulc_fuzz::fuzz_require(
        stats.points_read + stats.points_dropped_nonfinite == stats.points_in_file,
        "PLY: points read + dropped differ from the vertices in the file");
  } catch (const ulc::io::IoError&) {
    // A refused file: the expected outcome for most inputs.
  }
  return 0;
}
