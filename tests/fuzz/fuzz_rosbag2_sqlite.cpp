// Fuzzes the rosbag2 SQLite reader (ulc/bags/rosbag2_sqlite.hpp) on a .db3 file: the topics
// table, the messages query, CDR or ROS 1 payloads. SQLite itself is not instrumented, so
// coverage guidance sees only ULC's side.
// The recording is opened, then read to the end (fuzz_recording.hpp).
#include <cstddef>
#include <cstdint>

#include "fuzz_recording.hpp"
#include "fuzz_support.hpp"
#include "ulc/bags/rosbag2_sqlite.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = ulc_fuzz::input_file(data, size, "recording.db3");
  try {
    const ulc::bags::Rosbag2Sqlite source(path);
    ulc_fuzz::read_recording(source);
  } catch (const ulc::io::IoError&) {
    // A refused recording: the expected outcome for most inputs.
  }
  return 0;
}
