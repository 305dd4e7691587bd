// Fuzzes the ROS 1 bag reader (ulc/bags/ros1_bag.hpp): the bag header, then the index
// (connection, chunk info and index data records) or, when index_pos is 0, a linear scan;
// chunks none, bz2 or lz4.
// The recording is opened, then read to the end (fuzz_recording.hpp).
#include <cstddef>
#include <cstdint>

#include "fuzz_recording.hpp"
#include "fuzz_support.hpp"
#include "ulc/bags/ros1_bag.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = ulc_fuzz::input_file(data, size, "recording.bag");
  try {
    const ulc::bags::Ros1Bag source(path);
    ulc_fuzz::read_recording(source);
  } catch (const ulc::io::IoError&) {
    // A refused recording: the expected outcome for most inputs.
  }
  return 0;
}
