// Fuzzes the KITTI Velodyne .bin reader (ulc/io/kitti_bin.hpp) through its file entry point,
// so the whole-file read (ulc/io/file_bytes.hpp) is covered too.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "ulc/io/kitti_bin.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = ulc_fuzz::input_file(data, size, "frame.bin");
  try {
    ulc::io::ReadStats stats;
    const ulc::io::DecodedCloud cloud = ulc::io::read_kitti_bin_decoded(path, &stats);
    ulc_fuzz::check_decoded(cloud);
    ulc_fuzz::fuzz_require(stats.points_in_file == size / ulc::io::kKittiPointBytes,
                           "KITTI: point count is not the file size / 16");
    ulc_fuzz::fuzz_require(
        stats.points_read + stats.points_dropped_nonfinite == stats.points_in_file,
        "KITTI: points read + dropped differ from the points in the file");
  } catch (const ulc::io::IoError&) {
    // A refused file: a size that is not a multiple of 16.
  }
  return 0;
}
