// ByteReader: a bounded cursor over an in-memory file, used by every binary parser.
//
// Every read first checks that enough bytes remain and otherwise throws IoError
// "truncated <what>: ..." at the current byte offset, so parsers never read out of bounds and
// never need their own size arithmetic. Offsets are absolute within the file.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>

#include "ulc/io/endian.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::io {

class ByteReader {
 public:
  ByteReader(const unsigned char* data, std::size_t size, std::string file)
      : data_(data), size_(size), file_(std::move(file)) {}

  std::size_t offset() const { return pos_; }
  std::size_t size() const { return size_; }
  std::size_t remaining() const { return size_ - pos_; }
  bool at_end() const { return pos_ == size_; }
  const std::string& file() const { return file_; }
  const unsigned char* data() const { return data_; }

  /// Returns a pointer to the next n bytes and moves past them.
  const unsigned char* take(std::size_t n, const char* what) {
    require(n, what);
    const unsigned char* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  void skip(std::size_t n, const char* what) { take(n, what); }

  template <typename T>
  T read(Endian order, const char* what) {
    return load<T>(take(sizeof(T), what), order);
  }

  /// Next line without its "\n" (and without a trailing "\r"); false at the end of the data.
  bool read_line(std::string_view& line) {
    if (pos_ >= size_) return false;
    const char* begin = reinterpret_cast<const char*>(data_ + pos_);
    std::size_t n = 0;
    while (pos_ + n < size_ && data_[pos_ + n] != '\n') ++n;
    pos_ += n < size_ - pos_ ? n + 1 : n;
    if (n > 0 && begin[n - 1] == '\r') --n;
    line = std::string_view(begin, n);
    return true;
  }

  /// Throws IoError "truncated <what>" unless n more bytes are available.
  void require(std::size_t n, const char* what) const {
    if (n > size_ - pos_)
      fail(std::string("truncated ") + what + ": need " + std::to_string(n) + " bytes, only " +
           std::to_string(size_ - pos_) + " left");
  }

  [[noreturn]] void fail(const std::string& reason) const { fail_at(pos_, reason); }
  [[noreturn]] void fail_at(std::size_t offset, const std::string& reason) const {
    throw IoError(file_, at_byte(offset), reason);
  }

 private:
  const unsigned char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string file_;
};

}  // namespace ulc::io
