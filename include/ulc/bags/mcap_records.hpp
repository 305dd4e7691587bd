// The records of an MCAP file (https://mcap.dev/spec), shared by the reader (mcap_reader.hpp)
// and the writer (mcap_writer.hpp).
//
// A file is the magic "\x89MCAP0\r\n", a Header record, the data section (Schema, Channel,
// Message, Chunk, MessageIndex, Attachment, Metadata records, closed by a DataEnd record), an
// optional summary section (Schema, Channel, Statistics, ChunkIndex, AttachmentIndex,
// MetadataIndex, SummaryOffset records), a Footer record and the magic again. Every record is
//   u8 opcode, u64 content length, content
// little endian; a String is a u32 byte length and the bytes, a Map a u32 byte length and the
// key/value pairs. Records may grow new fields at their end, so a parser reads the fields it
// knows and ignores what follows. Every length read here is checked against the bytes that hold
// it before it is used, so a corrupted length is an IoError, never a large allocation.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/limits.hpp"
#include "ulc/io/endian.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags::mcap {

/// "\x89MCAP0\r\n": 0x30 ('0') is the major version.
constexpr std::array<unsigned char, 8> kMagic = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
constexpr std::size_t kMagicSize = kMagic.size();
/// u8 opcode + u64 content length in front of every record.
constexpr std::size_t kRecordHeaderSize = 9;
/// A Footer's content: summary_start, summary_offset_start, summary_crc.
constexpr std::size_t kFooterContentSize = 8 + 8 + 4;
/// A Message's fixed fields: channel_id, sequence, log_time, publish_time.
constexpr std::size_t kMessageFixedSize = 2 + 4 + 8 + 8;
/// One MessageIndex entry: log_time and offset inside the uncompressed chunk records.
constexpr std::size_t kIndexEntrySize = 16;

enum class Op : std::uint8_t {
  header = 0x01,
  footer = 0x02,
  schema = 0x03,
  channel = 0x04,
  message = 0x05,
  chunk = 0x06,
  message_index = 0x07,
  chunk_index = 0x08,
  attachment = 0x09,
  attachment_index = 0x0A,
  statistics = 0x0B,
  metadata = 0x0C,
  metadata_index = 0x0D,
  summary_offset = 0x0E,
  data_end = 0x0F,
};

inline std::string op_name(std::uint8_t op) {
  static const char* const names[] = {
      "Header",     "Footer",       "Schema",        "Channel",       "Message",
      "Chunk",      "MessageIndex", "ChunkIndex",    "Attachment",    "AttachmentIndex",
      "Statistics", "Metadata",     "MetadataIndex", "SummaryOffset", "DataEnd"};
  if (op >= 0x01 && op <= 0x0F) return names[op - 1];
  return "unknown (opcode " + std::to_string(op) + ")";
}

inline bool is(std::uint8_t op, Op expected) {
  return op == static_cast<std::uint8_t>(expected);
}

// ---------------------------------------------------------------------------------------------
// CRC-32 (IEEE 802.3 / zlib polynomial 0xEDB88320, reflected), slicing by 8: eight table lookups
// per 8 bytes instead of one per byte, ~4 times the speed of the byte-wise loop.

namespace detail {

struct Crc32Tables {
  std::uint32_t t[8][256];
};

constexpr Crc32Tables make_crc32_tables() {
  Crc32Tables r{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    r.t[0][i] = c;
  }
  // t[s][i]: the CRC of byte i followed by s zero bytes.
  for (std::uint32_t i = 0; i < 256; ++i)
    for (int s = 1; s < 8; ++s) r.t[s][i] = (r.t[s - 1][i] >> 8) ^ r.t[0][r.t[s - 1][i] & 0xFFu];
  return r;
}

inline constexpr Crc32Tables kCrc32Tables = make_crc32_tables();

}  // namespace detail

/// Continues a CRC-32 over n more bytes; start with crc = 0 (as zlib's crc32()).
inline std::uint32_t crc32_update(std::uint32_t crc, const unsigned char* p, std::size_t n) {
  const auto& t = detail::kCrc32Tables.t;
  std::uint32_t c = ~crc;
  while (n >= 8) {
    const std::uint32_t lo = io::load_le<std::uint32_t>(p) ^ c;
    const std::uint32_t hi = io::load_le<std::uint32_t>(p + 4);
    c = t[7][lo & 0xFFu] ^ t[6][(lo >> 8) & 0xFFu] ^ t[5][(lo >> 16) & 0xFFu] ^ t[4][lo >> 24] ^
        t[3][hi & 0xFFu] ^ t[2][(hi >> 8) & 0xFFu] ^ t[1][(hi >> 16) & 0xFFu] ^ t[0][hi >> 24];
    p += 8;
    n -= 8;
  }
  while (n-- > 0) c = t[0][(c ^ *p++) & 0xFFu] ^ (c >> 8);
  return ~c;
}

inline std::uint32_t crc32(const unsigned char* p, std::size_t n) {
  return crc32_update(0, p, n);
}

inline std::string hex32(std::uint32_t v) {
  static const char digits[] = "0123456789abcdef";
  std::string s = "0x00000000";
  for (int k = 0; k < 8; ++k) s[9 - k] = digits[(v >> (4 * k)) & 0xFu];
  return s;
}

// ---------------------------------------------------------------------------------------------
// Where parsed bytes sit, for error messages.

/// Bytes of the file starting at file offset `base`, or (inside_chunk) bytes of a compressed
/// chunk's decompressed records: their own positions are not file offsets, so errors name the
/// chunk record's offset and the position inside its records.
struct Place {
  const std::string& file;
  std::uint64_t base;
  bool inside_chunk = false;

  std::uint64_t offset_of(std::uint64_t pos) const { return inside_chunk ? base : base + pos; }

  [[noreturn]] void fail(std::uint64_t pos, const std::string& reason) const {
    const std::string where =
        inside_chunk ? " (at byte " + std::to_string(pos) + " of the chunk's uncompressed records)"
                     : std::string();
    throw io::IoError(file, io::at_byte(static_cast<std::size_t>(offset_of(pos))), reason + where);
  }
};

/// Reads the fields of one record's content, each read checked against the content's length.
class FieldReader {
 public:
  /// `content` holds `size` bytes; `pos` is the content's position in `place`.
  FieldReader(const unsigned char* content, std::uint64_t size, const Place& place,
              std::uint64_t pos, const char* record)
      : p_(content), size_(size), place_(place), pos_(pos), record_(record) {}

  std::uint8_t u8(const char* field) { return take<std::uint8_t>(field); }
  std::uint16_t u16(const char* field) { return take<std::uint16_t>(field); }
  std::uint32_t u32(const char* field) { return take<std::uint32_t>(field); }
  std::uint64_t u64(const char* field) { return take<std::uint64_t>(field); }

  /// A String: u32 length, bytes; at most kMaxStringBytes.
  std::string string(const char* field) {
    const std::uint32_t n = u32(field);
    if (n > kMaxStringBytes)
      fail(field, std::to_string(n) + " bytes, more than the " + std::to_string(kMaxStringBytes) +
                      " a string may hold");
    const unsigned char* s = bytes(n, field);
    return std::string(reinterpret_cast<const char*>(s), n);
  }

  /// u32- or u64-length-prefixed bytes (Schema data, Chunk records): a view, no copy.
  std::pair<const unsigned char*, std::uint64_t> prefixed_bytes32(const char* field) {
    const std::uint32_t n = u32(field);
    return {bytes(n, field), n};
  }
  std::pair<const unsigned char*, std::uint64_t> prefixed_bytes64(const char* field) {
    const std::uint64_t n = u64(field);
    return {bytes(n, field), n};
  }

  /// A Map or Array: u32 byte length, then `entry_size`-byte entries (0: any layout, skipped).
  std::pair<const unsigned char*, std::uint64_t> sequence(const char* field,
                                                          std::uint64_t entry_size) {
    const std::uint32_t n = u32(field);
    if (entry_size != 0 && n % entry_size != 0)
      fail(field, std::to_string(n) + " bytes, not a whole number of " +
                      std::to_string(entry_size) + "-byte entries");
    return {bytes(n, field), n};
  }

  std::uint64_t consumed() const { return at_; }
  std::uint64_t remaining() const { return size_ - at_; }

 private:
  template <typename T>
  T take(const char* field) {
    return io::load_le<T>(bytes(sizeof(T), field));
  }

  const unsigned char* bytes(std::uint64_t n, const char* field) {
    if (n > size_ - at_)
      place_.fail(pos_ + at_, std::string("truncated ") + record_ + " record: field " + field +
                                  " needs " + std::to_string(n) + " bytes, only " +
                                  std::to_string(size_ - at_) + " remain in the record");
    const unsigned char* s = p_ + at_;
    at_ += n;
    return s;
  }

  [[noreturn]] void fail(const char* field, const std::string& what) const {
    place_.fail(pos_ + at_, std::string(record_) + " record: field " + field + " claims " + what);
  }

  const unsigned char* p_;
  std::uint64_t size_;
  const Place& place_;
  std::uint64_t pos_;
  std::uint64_t at_ = 0;
  const char* record_;
};

// ---------------------------------------------------------------------------------------------
// The records the reader uses. Each parse_* takes the record's content (after opcode and length).

struct RecordHeader {
  std::uint8_t op = 0;
  std::uint64_t length = 0;  ///< content bytes after the 9-byte header
};

inline RecordHeader parse_record_header(const unsigned char* p) {
  return {p[0], io::load_le<std::uint64_t>(p + 1)};
}

/// A Header's profile ("ros1", "ros2", ...) and library strings.
struct HeaderRecord {
  std::string profile;
  std::string library;
};

inline HeaderRecord parse_header(const unsigned char* c, std::uint64_t n, const Place& place,
                                 std::uint64_t pos) {
  FieldReader r(c, n, place, pos, "Header");
  HeaderRecord h;
  h.profile = r.string("profile");
  h.library = r.string("library");
  return h;
}

struct SchemaRecord {
  std::uint16_t id = 0;
  std::string name;      ///< "sensor_msgs/msg/PointCloud2"
  std::string encoding;  ///< "ros2msg", "ros1msg", ...
};

inline SchemaRecord parse_schema(const unsigned char* c, std::uint64_t n, const Place& place,
                                 std::uint64_t pos) {
  FieldReader r(c, n, place, pos, "Schema");
  SchemaRecord s;
  s.id = r.u16("id");
  s.name = r.string("name");
  s.encoding = r.string("encoding");
  r.prefixed_bytes32("data");
  return s;
}

struct ChannelRecord {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;  ///< "cdr", "ros1", ...
};

inline ChannelRecord parse_channel(const unsigned char* c, std::uint64_t n, const Place& place,
                                   std::uint64_t pos) {
  FieldReader r(c, n, place, pos, "Channel");
  ChannelRecord ch;
  ch.id = r.u16("id");
  ch.schema_id = r.u16("schema_id");
  ch.topic = r.string("topic");
  ch.message_encoding = r.string("message_encoding");
  r.sequence("metadata", 0);
  return ch;
}

struct MessageHeader {
  std::uint16_t channel_id = 0;
  std::uint64_t log_time = 0;
  std::uint64_t data_size = 0;  ///< the data follows the fixed fields
};

inline MessageHeader parse_message(const unsigned char* c, std::uint64_t n, const Place& place,
                                   std::uint64_t pos) {
  if (n < kMessageFixedSize)
    place.fail(pos, "truncated Message record: " + std::to_string(n) +
                        " bytes, its fixed fields need " + std::to_string(kMessageFixedSize));
  MessageHeader m;
  m.channel_id = io::load_le<std::uint16_t>(c);
  m.log_time = io::load_le<std::uint64_t>(c + 6);
  m.data_size = n - kMessageFixedSize;
  return m;
}

struct ChunkHeader {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;
  std::string compression;
  std::uint64_t records_pos = 0;   ///< position of the records inside the content
  std::uint64_t records_size = 0;  ///< compressed size of the records
};

inline ChunkHeader parse_chunk(const unsigned char* c, std::uint64_t n, const Place& place,
                               std::uint64_t pos) {
  FieldReader r(c, n, place, pos, "Chunk");
  ChunkHeader h;
  h.message_start_time = r.u64("message_start_time");
  h.message_end_time = r.u64("message_end_time");
  h.uncompressed_size = r.u64("uncompressed_size");
  h.uncompressed_crc = r.u32("uncompressed_crc");
  h.compression = r.string("compression");
  const std::uint64_t before = r.consumed() + 8;
  h.records_size = r.prefixed_bytes64("records").second;
  h.records_pos = before;
  return h;
}

/// The offset of the records inside a Chunk record (from its opcode), for a compression name.
inline std::uint64_t chunk_records_pos(const std::string& compression) {
  return kRecordHeaderSize + 8 + 8 + 8 + 4 + 4 + compression.size() + 8;
}

struct ChunkIndexRecord {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;  ///< the whole Chunk record, opcode and length included
  std::vector<std::pair<std::uint16_t, std::uint64_t>> message_index_offsets;
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

/// Map<uint16, uint64> entries: 10 bytes each.
inline std::vector<std::pair<std::uint16_t, std::uint64_t>> parse_u16_u64_map(
    std::pair<const unsigned char*, std::uint64_t> bytes) {
  std::vector<std::pair<std::uint16_t, std::uint64_t>> map;
  map.reserve(static_cast<std::size_t>(bytes.second / 10));
  for (std::uint64_t k = 0; k + 10 <= bytes.second; k += 10)
    map.emplace_back(io::load_le<std::uint16_t>(bytes.first + k),
                     io::load_le<std::uint64_t>(bytes.first + k + 2));
  return map;
}

inline ChunkIndexRecord parse_chunk_index(const unsigned char* c, std::uint64_t n,
                                          const Place& place, std::uint64_t pos) {
  FieldReader r(c, n, place, pos, "ChunkIndex");
  ChunkIndexRecord x;
  x.message_start_time = r.u64("message_start_time");
  x.message_end_time = r.u64("message_end_time");
  x.chunk_start_offset = r.u64("chunk_start_offset");
  x.chunk_length = r.u64("chunk_length");
  x.message_index_offsets = parse_u16_u64_map(r.sequence("message_index_offsets", 10));
  x.message_index_length = r.u64("message_index_length");
  x.compression = r.string("compression");
  x.compressed_size = r.u64("compressed_size");
  x.uncompressed_size = r.u64("uncompressed_size");
  return x;
}

struct StatisticsRecord {
  std::uint64_t message_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  /// channel id -> message count; empty when the writer did not count per channel.
  std::vector<std::pair<std::uint16_t, std::uint64_t>> channel_message_counts;
};

inline StatisticsRecord parse_statistics(const unsigned char* c, std::uint64_t n,
                                         const Place& place, std::uint64_t pos) {
  FieldReader r(c, n, place, pos, "Statistics");
  StatisticsRecord s;
  s.message_count = r.u64("message_count");
  r.u16("schema_count");
  r.u32("channel_count");
  r.u32("attachment_count");
  r.u32("metadata_count");
  s.chunk_count = r.u32("chunk_count");
  s.message_start_time = r.u64("message_start_time");
  s.message_end_time = r.u64("message_end_time");
  s.channel_message_counts = parse_u16_u64_map(r.sequence("channel_message_counts", 10));
  return s;
}

struct FooterRecord {
  std::uint64_t summary_start = 0;
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};

inline FooterRecord parse_footer(const unsigned char* c) {
  return {io::load_le<std::uint64_t>(c), io::load_le<std::uint64_t>(c + 8),
          io::load_le<std::uint32_t>(c + 16)};
}

/// A MessageIndex record's entries: (log_time u64, offset u64) pairs.
struct MessageIndexRecord {
  std::uint16_t channel_id = 0;
  const unsigned char* entries = nullptr;
  std::uint64_t count = 0;
};

inline MessageIndexRecord parse_message_index(const unsigned char* c, std::uint64_t n,
                                              const Place& place, std::uint64_t pos) {
  FieldReader r(c, n, place, pos, "MessageIndex");
  MessageIndexRecord m;
  m.channel_id = r.u16("channel_id");
  const auto entries = r.sequence("records", kIndexEntrySize);
  m.entries = entries.first;
  m.count = entries.second / kIndexEntrySize;
  return m;
}

/// The codec of a Chunk's compression name: "" (none), "zstd", "lz4" (LZ4 frame).
inline std::optional<Codec> codec_of(const std::string& compression) {
  if (compression.empty()) return Codec::none;
  if (compression == "zstd") return Codec::zstd;
  if (compression == "lz4") return Codec::lz4;
  return std::nullopt;
}

inline std::string compression_name(Codec codec) {
  switch (codec) {
    case Codec::zstd:
      return "zstd";
    case Codec::lz4:
      return "lz4";
    default:
      return "";
  }
}

// ---------------------------------------------------------------------------------------------
// Serialisation for the writer.

inline void put_u8(std::vector<unsigned char>& b, std::uint8_t v) {
  b.push_back(v);
}
inline void put_u16(std::vector<unsigned char>& b, std::uint16_t v) {
  unsigned char s[2];
  io::store_le(s, v);
  b.insert(b.end(), s, s + 2);
}
inline void put_u32(std::vector<unsigned char>& b, std::uint32_t v) {
  unsigned char s[4];
  io::store_le(s, v);
  b.insert(b.end(), s, s + 4);
}
inline void put_u64(std::vector<unsigned char>& b, std::uint64_t v) {
  unsigned char s[8];
  io::store_le(s, v);
  b.insert(b.end(), s, s + 8);
}
inline void put_string(std::vector<unsigned char>& b, const std::string& s) {
  put_u32(b, static_cast<std::uint32_t>(s.size()));
  b.insert(b.end(), s.begin(), s.end());
}
inline void put_record_header(std::vector<unsigned char>& b, Op op, std::uint64_t length) {
  put_u8(b, static_cast<std::uint8_t>(op));
  put_u64(b, length);
}

}  // namespace ulc::bags::mcap
