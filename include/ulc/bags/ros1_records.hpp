// The records of a ROS 1 bag, format 2.0 (http://wiki.ros.org/Bags/Format/2.0), shared by the
// reader (ros1_bag.hpp) and the writer (ros1_bag_writer.hpp).
//
// A bag is the magic line "#ROSBAG V2.0\n" followed by records, each
//   u32 header_len, header, u32 data_len, data
// whose header is a list of fields "u32 field_len, name=value" (little endian). The field `op`
// says what the record is: bag header, chunk, connection, message data, index data, chunk info.
// Every length read here is checked against the bytes that hold it before it is used.
#pragma once

#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/limits.hpp"
#include "ulc/io/endian.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags::ros1 {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::size_t kMagicSize = sizeof(kMagic) - 1;
/// rosbag pads the bag header record (header and data) to 4096 bytes so that it can be
/// rewritten in place when the recording closes.
constexpr std::uint32_t kBagHeaderPadded = 4096;
/// A record header holds a few short fields; a longer one is corrupted.
constexpr std::uint64_t kMaxHeaderBytes = kMaxStringBytes;

/// The `op` codes of the format 2.0 records.
enum class Op : std::uint8_t {
  message_data = 0x02,
  bag_header = 0x03,
  index_data = 0x04,
  chunk = 0x05,
  chunk_info = 0x06,
  connection = 0x07,
};

inline std::string op_name(std::uint8_t op) {
  switch (static_cast<Op>(op)) {
    case Op::message_data:
      return "message data";
    case Op::bag_header:
      return "bag header";
    case Op::index_data:
      return "index data";
    case Op::chunk:
      return "chunk";
    case Op::chunk_info:
      return "chunk info";
    case Op::connection:
      return "connection";
  }
  return "unknown (op " + std::to_string(op) + ")";
}

/// ROS time (u32 seconds, u32 nanoseconds) as nanoseconds; any u32 pair fits an int64.
inline std::int64_t load_time(const unsigned char* p) {
  const auto sec = io::load_le<std::uint32_t>(p);
  const auto nsec = io::load_le<std::uint32_t>(p + 4);
  return static_cast<std::int64_t>(sec) * 1000000000 + nsec;
}

/// True when a time in nanoseconds can be stored as ROS time.
inline bool representable_time(std::int64_t ns) {
  return ns >= 0 && ns / 1000000000 <= std::int64_t{0xffffffff};
}

inline void store_time(unsigned char* p, std::int64_t ns) {
  io::store_le(p, static_cast<std::uint32_t>(ns / 1000000000));
  io::store_le(p + 4, static_cast<std::uint32_t>(ns % 1000000000));
}

/// Where a buffer of records lies, for error messages: at byte `origin` of the file, or inside
/// the compressed chunk whose record starts at byte `origin` (its own bytes have no file offset).
struct Place {
  const std::string* file = nullptr;
  std::uint64_t origin = 0;
  Codec compressed = Codec::none;

  /// IoError for the byte `at` of the buffer.
  [[noreturn]] void fail(std::uint64_t at, const std::string& reason) const {
    if (compressed == Codec::none)
      throw io::IoError(*file, io::at_byte(static_cast<std::size_t>(origin + at)), reason);
    throw io::IoError(*file, io::at_byte(static_cast<std::size_t>(origin)),
                      std::string("in the ") + codec_name(compressed) + " chunk, byte " +
                          std::to_string(at) + " of its decompressed data: " + reason);
  }
};

/// The fields of a record header (or of a connection header, which has the same layout),
/// checked when constructed: every field's length lies inside the header, every field has '='.
class FieldList {
 public:
  /// `p` holds `size` bytes found at byte `at` of `place`.
  FieldList(const unsigned char* p, std::size_t size, const Place& place, std::uint64_t at)
      : p_(p), size_(size), place_(place), at_(at) {
    for (std::size_t pos = 0; pos < size_;) pos = check_field(pos);
  }

  std::optional<std::string_view> find(std::string_view name) const {
    for (std::size_t pos = 0; pos < size_;) {
      const std::size_t len = io::load_le<std::uint32_t>(p_ + pos);
      const char* field = reinterpret_cast<const char*>(p_ + pos + 4);
      if (len > name.size() && field[name.size()] == '=' &&
          std::memcmp(field, name.data(), name.size()) == 0)
        return std::string_view(field + name.size() + 1, len - name.size() - 1);
      pos += 4 + len;
    }
    return std::nullopt;
  }

  /// The field's value; IoError when it is missing.
  std::string_view text(std::string_view name) const {
    const auto value = find(name);
    if (!value) fail("missing header field '" + std::string(name) + "'");
    return *value;
  }
  std::uint8_t op() const { return sized(std::string_view("op"), 1)[0]; }
  std::uint32_t u32(std::string_view name) const {
    return io::load_le<std::uint32_t>(sized(name, 4));
  }
  std::uint64_t u64(std::string_view name) const {
    return io::load_le<std::uint64_t>(sized(name, 8));
  }
  std::int64_t time(std::string_view name) const { return load_time(sized(name, 8)); }

  [[noreturn]] void fail(const std::string& reason) const { place_.fail(at_, reason); }

 private:
  std::size_t check_field(std::size_t pos) const {
    if (size_ - pos < 4) place_.fail(at_ + pos, "truncated header field length");
    const std::uint32_t len = io::load_le<std::uint32_t>(p_ + pos);
    if (len > size_ - pos - 4)
      place_.fail(at_ + pos, "header field of " + std::to_string(len) +
                                 " bytes runs past the end of its header (" +
                                 std::to_string(size_) + " bytes)");
    if (std::memchr(p_ + pos + 4, '=', len) == nullptr)
      place_.fail(at_ + pos, "header field without '='");
    return pos + 4 + len;
  }

  /// The value of a binary field that must hold exactly `n` bytes.
  const unsigned char* sized(std::string_view name, std::size_t n) const {
    const std::string_view value = text(name);
    if (value.size() != n)
      fail("header field '" + std::string(name) + "' holds " + std::to_string(value.size()) +
           " bytes, expected " + std::to_string(n));
    return reinterpret_cast<const unsigned char*>(value.data());
  }

  const unsigned char* p_;
  std::size_t size_;
  Place place_;
  std::uint64_t at_;
};

/// Where the parts of one record lie (offsets in the file, or in a decompressed chunk).
struct RecordSpan {
  std::uint64_t pos = 0;  ///< first byte of the record (its header length)
  std::uint64_t header_at = 0;
  std::uint64_t header_size = 0;
  std::uint64_t data_at = 0;
  std::uint64_t data_size = 0;
  std::uint64_t end() const { return data_at + data_size; }
};

/// The record at byte `at` of a buffer of `size` bytes (a decompressed chunk, or the index data
/// records after a chunk: `container` names it for errors).
inline RecordSpan record_in_buffer(const unsigned char* p, std::uint64_t size, std::uint64_t at,
                                   const Place& place, const char* container) {
  const auto past_end = [&](const std::string& what) {
    place.fail(at, what + " runs past the end of the " + container + " (" + std::to_string(size) +
                       " bytes)");
  };
  if (at > size || size - at < 4) past_end("truncated record: its header length");
  RecordSpan r;
  r.pos = at;
  r.header_at = at + 4;
  r.header_size = io::load_le<std::uint32_t>(p + at);
  if (r.header_size > size - r.header_at || size - r.header_at - r.header_size < 4)
    past_end("record header of " + std::to_string(r.header_size) + " bytes");
  r.data_at = r.header_at + r.header_size + 4;
  r.data_size = io::load_le<std::uint32_t>(p + r.data_at - 4);
  if (r.data_size > size - r.data_at)
    past_end("record data of " + std::to_string(r.data_size) + " bytes");
  return r;
}

/// Reads the lengths and the header (into `header`) of the record at byte `pos` of the file.
/// Returns nothing when the record runs past the end of the file (a cut recording); lengths
/// beyond the limits are IoErrors.
inline std::optional<RecordSpan> try_read_record(const FileReader& file, std::uint64_t pos,
                                                 std::vector<unsigned char>& header) {
  const std::uint64_t size = file.size();
  if (pos > size || size - pos < 4) return std::nullopt;
  unsigned char len[4];
  file.read_into(pos, len, 4, "record header length");
  RecordSpan r;
  r.pos = pos;
  r.header_at = pos + 4;
  r.header_size = io::load_le<std::uint32_t>(len);
  if (r.header_size > kMaxHeaderBytes)
    file.fail(pos, "record header claims " + std::to_string(r.header_size) +
                       " bytes, more than the 16 MiB a header may hold");
  if (size - r.header_at < r.header_size + 4) return std::nullopt;
  file.read_at(r.header_at, r.header_size + 4, header, "record header");
  r.data_at = r.header_at + r.header_size + 4;
  r.data_size = io::load_le<std::uint32_t>(header.data() + r.header_size);
  header.resize(static_cast<std::size_t>(r.header_size));
  if (r.data_size > kMaxRecordBytes)
    file.fail(pos, "record data claims " + std::to_string(r.data_size) +
                       " bytes, more than the 1 GiB a record may hold");
  if (size - r.data_at < r.data_size) return std::nullopt;
  return r;
}

/// As try_read_record, with a record that runs past the end of the file an IoError.
inline RecordSpan read_record(const FileReader& file, std::uint64_t pos,
                              std::vector<unsigned char>& header, const char* what) {
  const auto r = try_read_record(file, pos, header);
  if (!r)
    file.fail(pos, std::string("truncated ") + what +
                       " record: it runs past the end of the file (" + std::to_string(file.size()) +
                       " bytes)");
  return *r;
}

/// Builds a record header (or a connection header) field by field, for the writer.
class FieldWriter {
 public:
  FieldWriter& text(std::string_view name, std::string_view value) {
    return bytes(name, reinterpret_cast<const unsigned char*>(value.data()), value.size());
  }
  FieldWriter& op(Op op) {
    const auto b = static_cast<unsigned char>(op);
    return bytes("op", &b, 1);
  }
  FieldWriter& u32(std::string_view name, std::uint32_t v) {
    unsigned char b[4];
    io::store_le(b, v);
    return bytes(name, b, 4);
  }
  FieldWriter& u64(std::string_view name, std::uint64_t v) {
    unsigned char b[8];
    io::store_le(b, v);
    return bytes(name, b, 8);
  }
  FieldWriter& time(std::string_view name, std::int64_t ns) {
    unsigned char b[8];
    store_time(b, ns);
    return bytes(name, b, 8);
  }
  const std::vector<unsigned char>& data() const { return out_; }

 private:
  FieldWriter& bytes(std::string_view name, const unsigned char* v, std::size_t n) {
    unsigned char len[4];
    io::store_le(len, static_cast<std::uint32_t>(name.size() + 1 + n));
    out_.insert(out_.end(), len, len + 4);
    out_.insert(out_.end(), name.begin(), name.end());
    out_.push_back('=');
    out_.insert(out_.end(), v, v + n);
    return *this;
  }

  std::vector<unsigned char> out_;
};

}  // namespace ulc::bags::ros1
