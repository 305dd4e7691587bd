// Shared pieces of the fuzz targets: the input as a file, the properties every successful parse
// must have, and a full read of a recording.
//
// A target catches ulc::io::IoError (the one way a parser may refuse its input) and lets
// everything else escape, so libFuzzer reports any other exception, crash, sanitizer report or
// broken property (fuzz_require aborts) as a finding.
#pragma once

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <numeric>
#include <string>
#include <system_error>
#include <vector>

#include "ulc/io/decoded_cloud.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc_fuzz {

/// Aborts with `what` when a property that every accepted input must have does not hold.
inline void fuzz_require(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "ulc fuzz: property violated: %s\n", what);
  std::abort();
}

/// Where scratch files go: $ULC_FUZZ_SCRATCH when set (scripts/fuzz.sh points it into a folder
/// it removes, so a crashed run leaves nothing behind), else /dev/shm (tmpfs) when there is one,
/// else the temporary directory.
inline std::filesystem::path scratch_root() {
  if (const char* dir = std::getenv("ULC_FUZZ_SCRATCH"); dir != nullptr && *dir != '\0') return dir;
  std::error_code ec;
  if (std::filesystem::is_directory("/dev/shm", ec) && ::access("/dev/shm", W_OK) == 0)
    return "/dev/shm";
  return std::filesystem::temp_directory_path();
}

/// A folder of this process's own for the input files, removed at exit.
class ScratchFolder {
 public:
  ScratchFolder()
      : path_(scratch_root() / ("ulc_fuzz_" + std::to_string(static_cast<long>(::getpid())))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Writes the fuzz input to `<scratch>/<name>` (replacing the previous one) and returns the path.
inline std::filesystem::path input_file(const std::uint8_t* data, std::size_t size,
                                        const std::string& name) {
  static const ScratchFolder folder;
  const std::filesystem::path path = folder.path() / name;
  // A new file rather than a truncated one: on ext4, truncating a file that holds data makes
  // close() wait for its write-back (auto_da_alloc), which cost milliseconds per input.
  std::error_code ec;
  std::filesystem::remove(path, ec);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  fuzz_require(static_cast<bool>(out), "the fuzz input could not be written to a scratch file");
  return path;
}

/// What every reader promises about a DecodedCloud (ulc/io/decoded_cloud.hpp).
inline void check_decoded(const ulc::io::DecodedCloud& cloud) {
  const std::size_t n = cloud.size();
  fuzz_require(cloud.intensities.empty() || cloud.intensities.size() == n,
               "intensities: neither empty nor one per point");
  fuzz_require(cloud.times.empty() || cloud.times.size() == n,
               "times: neither empty nor one per point");
  for (const auto& p : cloud.points) fuzz_require(p.allFinite(), "a non-finite point was kept");
}

/// Reads every byte of a message so that AddressSanitizer checks the whole view.
inline void touch(const unsigned char* data, std::size_t size) {
  unsigned sum = 0;
  for (std::size_t i = 0; i < size; ++i) sum += data[i];
  volatile unsigned sink = sum;
  (void)sink;
}

}  // namespace ulc_fuzz
