// Reading and writing message fields in the two serialisations of ROS:
//   ROS 1: little endian, fields packed with no alignment; strings and variable arrays are a
//          u32 count then the elements; a time is u32 sec + u32 nsec.
//   CDR (ROS 2, XCDR1): a 4-byte encapsulation header (00 00 big endian, 00 01 little endian),
//          then each primitive aligned to its own size (at most 8) counted from the end of that
//          header; strings are a u32 length that includes a terminating NUL; a time is
//          i32 sec + u32 nanosec.
// MessageReader checks every read against the message's size, so a corrupted length fails as an
// io::IoError naming the file, the message's byte offset and the field, never as a large
// allocation or an out-of-bounds read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ulc/bags/limits.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/io/endian.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

class MessageReader {
 public:
  /// `type` names the message in errors ("sensor_msgs/PointCloud2").
  MessageReader(const MessageView& message, Serialization serialization, std::string type)
      : data_(message.data),
        size_(message.size),
        file_(message.file ? *message.file : std::string("<memory>")),
        offset_(message.offset),
        type_(std::move(type)),
        cdr_(serialization == Serialization::cdr) {
    if (cdr_) read_encapsulation();
  }

  io::Endian order() const { return order_; }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return size_ - pos_; }

  template <typename T>
  T read(const char* field) {
    align(sizeof(T));
    return io::load<T>(take(sizeof(T), field), order_);
  }

  bool read_bool(const char* field) { return read<std::uint8_t>(field) != 0; }

  /// A string (ROS 1: without NUL; CDR: the length counts a final NUL, dropped here).
  std::string_view read_string(const char* field) {
    const std::uint32_t n = read<std::uint32_t>(field);
    if (n > kMaxStringBytes || n > remaining())
      fail(std::string("field '") + field + "' claims a string of " + std::to_string(n) +
           " bytes, only " + std::to_string(remaining()) + " left in the message");
    const char* p = reinterpret_cast<const char*>(take(n, field));
    std::size_t len = n;
    if (cdr_ && len > 0 && p[len - 1] == '\0') --len;
    return std::string_view(p, len);
  }

  /// The count of a variable-length array whose elements take at least `min_element_bytes`
  /// each: checked against the bytes left, so no count can make the caller over-allocate.
  std::uint32_t read_count(std::size_t min_element_bytes, const char* field) {
    const std::uint32_t n = read<std::uint32_t>(field);
    if (n > kMaxArrayElements || static_cast<std::uint64_t>(n) * min_element_bytes > remaining())
      fail(std::string("field '") + field + "' claims " + std::to_string(n) +
           " elements, more than the " + std::to_string(remaining()) + " bytes left hold");
    return n;
  }

  /// A time (header.stamp) as nanoseconds since the epoch.
  std::int64_t read_time(const char* field) {
    const std::int64_t sec = cdr_ ? static_cast<std::int64_t>(read<std::int32_t>(field))
                                  : static_cast<std::int64_t>(read<std::uint32_t>(field));
    const std::uint32_t nsec = read<std::uint32_t>(field);
    if (nsec >= 1000000000u)
      fail(std::string("field '") + field + "' has " + std::to_string(nsec) +
           " nanoseconds (must be below 1e9)");
    return sec * 1000000000 + static_cast<std::int64_t>(nsec);
  }

  /// n raw bytes (a uint8[] payload), aligned to nothing.
  const unsigned char* take(std::size_t n, const char* field) {
    if (n > remaining())
      fail(std::string("truncated field '") + field + "': needs " + std::to_string(n) +
           " bytes, only " + std::to_string(remaining()) + " left in the message");
    const unsigned char* p = data_ + pos_;
    pos_ += n;
    return p;
  }

  /// CDR: skips padding up to a multiple of n counted from the end of the encapsulation header.
  void align(std::size_t n) {
    if (!cdr_ || n <= 1) return;
    const std::size_t rel = pos_ - kEncapsulationBytes;
    const std::size_t pad = (n - rel % n) % n;
    if (pad > remaining()) fail("truncated message: padding runs past its end");
    pos_ += pad;
  }

  [[noreturn]] void fail(const std::string& reason) const {
    throw io::IoError(file_, io::at_byte(static_cast<std::size_t>(offset_)),
                      type_ + " message: " + reason + " (at byte " + std::to_string(pos_) + " of " +
                          std::to_string(size_) + ")");
  }

 private:
  static constexpr std::size_t kEncapsulationBytes = 4;

  void read_encapsulation() {
    const unsigned char* h = take(kEncapsulationBytes, "CDR encapsulation header");
    if (h[0] != 0 || h[1] > 1)
      fail("unsupported CDR encapsulation " + std::to_string(h[0]) + " " + std::to_string(h[1]) +
           " (expected plain CDR: 00 00 or 00 01)");
    order_ = h[1] == 1 ? io::Endian::little : io::Endian::big;
  }

  const unsigned char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string file_;
  std::uint64_t offset_;
  std::string type_;
  bool cdr_;
  io::Endian order_ = io::Endian::little;
};

/// Builds a message in either serialisation (for our writers: tests, benchmarks, conversions).
class MessageWriter {
 public:
  explicit MessageWriter(Serialization serialization, io::Endian order = io::Endian::little)
      : cdr_(serialization == Serialization::cdr), order_(cdr_ ? order : io::Endian::little) {
    if (cdr_) bytes_ = {0, static_cast<unsigned char>(order_ == io::Endian::little ? 1 : 0), 0, 0};
  }

  template <typename T>
  void write(T value) {
    align(sizeof(T));
    const std::size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    io::store<T>(bytes_.data() + at, value, order_);
  }
  void write_bool(bool v) { write<std::uint8_t>(v ? 1 : 0); }
  void write_string(std::string_view s) {
    write<std::uint32_t>(static_cast<std::uint32_t>(s.size() + (cdr_ ? 1 : 0)));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    if (cdr_) bytes_.push_back(0);
  }
  void write_count(std::size_t n) { write<std::uint32_t>(static_cast<std::uint32_t>(n)); }
  void write_time(std::int64_t ns) {
    const std::int64_t sec = ns >= 0 ? ns / 1000000000 : -((-ns + 999999999) / 1000000000);
    const auto nsec = static_cast<std::uint32_t>(ns - sec * 1000000000);
    if (cdr_)
      write<std::int32_t>(static_cast<std::int32_t>(sec));
    else
      write<std::uint32_t>(static_cast<std::uint32_t>(sec));
    write<std::uint32_t>(nsec);
  }
  void write_bytes(const unsigned char* p, std::size_t n) { bytes_.insert(bytes_.end(), p, p + n); }
  void align(std::size_t n) {
    if (!cdr_ || n <= 1) return;
    while ((bytes_.size() - 4) % n != 0) bytes_.push_back(0);
  }

  io::Endian order() const { return order_; }
  const std::vector<unsigned char>& bytes() const { return bytes_; }
  std::vector<unsigned char> release() { return std::move(bytes_); }

 private:
  bool cdr_;
  io::Endian order_;
  std::vector<unsigned char> bytes_;
};

}  // namespace ulc::bags
