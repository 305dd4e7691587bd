// Fuzzes the MCAP reader (ulc/bags/mcap_reader.hpp): magic, header, the summary section
// (or a walk of the data section without one), chunks none, zstd or lz4, message indexes.
// The recording is opened, then read to the end (fuzz_recording.hpp).
#include <cstddef>
#include <cstdint>

#include "fuzz_recording.hpp"
#include "fuzz_support.hpp"
#include "ulc/bags/mcap_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = ulc_fuzz::input_file(data, size, "recording.mcap");
  try {
    const ulc::bags::McapReader source(path);
    ulc_fuzz::read_recording(source);
  } catch (const ulc::io::IoError&) {
    // A refused recording: the expected outcome for most inputs.
  }
  return 0;
}
