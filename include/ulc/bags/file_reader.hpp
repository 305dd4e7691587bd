// FileReader: positioned reads from a recording too large to load whole (pread), every read
// checked against the file's size, every failure an IoError naming the file and the byte.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "ulc/bags/limits.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

class FileReader {
 public:
  explicit FileReader(const std::filesystem::path& path) : name_(path.string()) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw io::IoError(name_, "", "no such file");
    if (std::filesystem::is_directory(path, ec))
      throw io::IoError(name_, "", "is a folder, expected a file");
    fd_ = ::open(name_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0)
      throw io::IoError(name_, "", std::string("cannot open for reading: ") + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd_, &st) != 0) {
      ::close(fd_);
      throw io::IoError(name_, "", "cannot determine the file size");
    }
    size_ = static_cast<std::uint64_t>(st.st_size);
  }
  FileReader(const FileReader&) = delete;
  FileReader& operator=(const FileReader&) = delete;
  ~FileReader() {
    if (fd_ >= 0) ::close(fd_);
  }

  const std::string& name() const { return name_; }
  std::uint64_t size() const { return size_; }

  /// Reads n bytes at `offset` into `out` (resized to n). `what` names the data for the error
  /// "truncated <what>: need n bytes at byte offset, the file ends at byte size".
  void read_at(std::uint64_t offset, std::uint64_t n, std::vector<unsigned char>& out,
               const char* what) const {
    require(offset, n, what);
    out.resize(static_cast<std::size_t>(n));
    read_into(offset, out.data(), n);
  }

  /// Reads n bytes at `offset` into `dest`, which must hold n bytes.
  void read_into(std::uint64_t offset, unsigned char* dest, std::uint64_t n,
                 const char* what = "data") const {
    require(offset, n, what);
    std::uint64_t done = 0;
    while (done < n) {
      const ssize_t got = ::pread(fd_, dest + done, static_cast<std::size_t>(n - done),
                                  static_cast<off_t>(offset + done));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0)
        throw io::IoError(name_, io::at_byte(static_cast<std::size_t>(offset + done)),
                          got < 0 ? std::string("read failed: ") + std::strerror(errno)
                                  : std::string("unexpected end of file"));
      done += static_cast<std::uint64_t>(got);
    }
  }

  /// IoError unless n bytes from `offset` lie inside the file and n is at most kMaxRecordBytes.
  void require(std::uint64_t offset, std::uint64_t n, const char* what) const {
    if (n > kMaxRecordBytes)
      fail(offset, std::string(what) + " claims " + std::to_string(n) +
                       " bytes, more than the 1 GiB a record may hold");
    if (offset > size_ || n > size_ - offset)
      fail(offset, std::string("truncated ") + what + ": need " + std::to_string(n) +
                       " bytes, the file ends at byte " + std::to_string(size_));
  }

  [[noreturn]] void fail(std::uint64_t offset, const std::string& reason) const {
    throw io::IoError(name_, io::at_byte(static_cast<std::size_t>(offset)), reason);
  }

 private:
  std::string name_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

}  // namespace ulc::bags
