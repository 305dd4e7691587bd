// McapReader: the MessageSource of an MCAP file (ROS 2's default bag storage; also ROS 1
// messages), read by byte offsets, a bounded part of the file in memory.
//
// Opening
//   - With a summary section (Footer.summary_start != 0): Schema, Channel, Statistics and
//     ChunkIndex records come from it, checked against Footer.summary_crc when nonzero. The data
//     section is then walked record by record, jumping over every chunk that a ChunkIndex with
//     message indexes describes (one small read per chunk): the walk finds what the index does
//     not cover -- messages outside chunks, chunks without message indexes (decompressed once to
//     list their messages) -- and checks that every indexed chunk starts where its index says.
//     Message counts come from Statistics.channel_message_counts; first and last times from the
//     MessageIndex records of the few chunks that can hold a topic's earliest or latest message
//     (chunks sorted by their start / end times). Without per-channel statistics every chunk's
//     MessageIndex records are read to count.
//   - Without a summary (summary_start 0): a linear scan of the data section decompresses each
//     chunk once and lists its messages. warnings() says so.
//   - Without a Footer and closing magic, the file was cut short (or its recorder never closed
//     it): an IoError at the end of the file. Nothing of a damaged file is read silently.
//
// Reading: a cursor lists the (log_time, chunk, offset) of the selected messages -- from the
// MessageIndex records of the selected channels (ChunkIndex.message_index_offsets), only for
// chunks whose time range meets the window -- sorts them, and walks the list, decompressing a
// chunk when first needed. A chunk stays cached until its last listed message has been read
// (at most kMaxCachedChunks, least recently used evicted), so time-sorted chunks are
// decompressed once and overlapping ones work.
//
// Checks: Chunk.uncompressed_crc (when nonzero) on every decompression; Footer.summary_crc (when
// nonzero); DataEnd.data_section_crc (when nonzero) only when the linear scan read the whole
// data section -- an indexed file is not read whole just for that CRC. Chunk compression "",
// "zstd", "lz4" (LZ4 frame); any other is an IoError naming it. Unknown opcodes are skipped, as
// the specification asks.
//
// Topics: one TopicInfo per topic name (`connections` = its channels), type = the Schema name
// ("sensor_msgs/msg/PointCloud2"; "" for channels without schema), serialization from the
// channel's message_encoding: "cdr" -> cdr, "ros1" -> ros1. Topics of other encodings (json,
// protobuf, ...) are listed with their counts, but a cursor selecting one throws IoError
// "message encoding X is not supported"; so does a topic whose channels disagree on the encoding.
//
// MessageView: data points into the (decompressed) chunk, no copy; offset is the Message
// record's file offset for uncompressed chunks and messages outside chunks, the Chunk record's
// offset for compressed chunks; time_ns = log_time.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/limits.hpp"
#include "ulc/bags/mcap_records.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

namespace mcap {

/// Decompressed chunks a cursor keeps at once (chunks overlapping in time).
constexpr std::size_t kMaxCachedChunks = 8;
/// Read-ahead of the data-section walk and of messages outside chunks.
constexpr std::size_t kWindowBytes = std::size_t{1} << 20;
/// Entry::chunk of a message outside any chunk.
constexpr std::uint32_t kLoose = std::numeric_limits<std::uint32_t>::max();

struct ChannelInfo {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string encoding;
  std::uint64_t record_offset = 0;  ///< where its Channel record is (for error messages)
  std::size_t topic_index = 0;
};

/// A Chunk record and where its MessageIndex records are.
struct ChunkRef {
  std::uint64_t offset = 0;  ///< of the Chunk record
  std::uint64_t length = 0;  ///< of the whole record, opcode and length included
  std::int64_t start_time = 0;
  std::int64_t end_time = 0;
  Codec codec = Codec::none;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint64_t index_offset = 0;  ///< the MessageIndex records right after the chunk
  std::uint64_t index_length = 0;
  std::vector<std::pair<std::uint16_t, std::uint64_t>> index_offsets;  ///< channel -> record
  bool indexed = false;  ///< messages listed through index_offsets (else found by the walk)
  bool seen = false;     ///< the data-section walk met it where the index says
};

/// One message: where it is and when. 24 bytes.
struct Entry {
  std::int64_t time = 0;
  std::uint64_t pos = 0;  ///< in the chunk's uncompressed records, or the file offset (kLoose)
  std::uint32_t chunk = kLoose;
  std::uint32_t topic = 0;  ///< topic index (channel slot while the file is being indexed)
};

/// Everything known about the file once opened.
struct FileIndex {
  std::vector<ChannelInfo> channels;
  std::vector<std::int32_t> channel_slot = std::vector<std::int32_t>(65536, -1);  ///< id -> slot
  std::map<std::uint16_t, SchemaRecord> schemas;
  std::vector<ChunkRef> chunks;
  std::vector<Entry> scanned;  ///< messages found by the walk (outside chunks, unindexed chunks)
  std::vector<TopicInfo> topics;
  std::vector<std::string> topic_problem;   ///< why a cursor cannot read a topic ("" = it can)
  std::vector<std::uint64_t> topic_offset;  ///< its first Channel record, for errors
  std::vector<std::string> warnings;

  std::int32_t slot_of(std::uint16_t channel_id) const { return channel_slot[channel_id]; }
};

/// Reads through a read-ahead buffer: the walk over a data section's records, the messages
/// outside chunks. A read that continues the buffer reads ahead kWindowBytes; one that jumps
/// (over an indexed chunk) reads ahead only kJumpBytes, so jumping over a chunk costs one small
/// read. A pointer returned stays valid until the next get().
class ReadWindow {
 public:
  explicit ReadWindow(const FileReader& file) : file_(file) {}

  const unsigned char* get(std::uint64_t offset, std::uint64_t n, const char* what) {
    if (offset >= start_ && n <= size_ && offset - start_ <= size_ - n)
      return buf_.data() + (offset - start_);
    file_.require(offset, n, what);
    const std::uint64_t ahead = offset == start_ + size_ ? kWindowBytes : kJumpBytes;
    const std::uint64_t want =
        std::max<std::uint64_t>(n, std::min<std::uint64_t>(ahead, file_.size() - offset));
    buf_.resize(static_cast<std::size_t>(want));
    file_.read_into(offset, buf_.data(), want, what);
    start_ = offset;
    size_ = want;
    return buf_.data();
  }

 private:
  static constexpr std::uint64_t kJumpBytes = 4096;
  const FileReader& file_;
  std::vector<unsigned char> buf_;
  std::uint64_t start_ = 0;
  std::uint64_t size_ = 0;
};

/// The uncompressed records of a Chunk record held in memory.
struct ChunkRecords {
  const unsigned char* data = nullptr;
  std::uint64_t size = 0;
  ChunkHeader header;
};

/// Parses the Chunk record `record` (n bytes, opcode included) found at file offset `offset`,
/// decompresses its records into `out` (uncompressed records are used in place), checks the
/// CRC when the chunk has one.
inline ChunkRecords open_chunk(const unsigned char* record, std::uint64_t n, std::uint64_t offset,
                               const std::string& file, std::vector<unsigned char>& out) {
  const Place place{file, offset};
  const RecordHeader rh = parse_record_header(record);
  if (!is(rh.op, Op::chunk) || rh.length != n - kRecordHeaderSize)
    place.fail(0, "expected a Chunk record of " + std::to_string(n) + " bytes, found " +
                      op_name(rh.op) + " with " + std::to_string(rh.length) + " content bytes");
  ChunkRecords r;
  r.header = parse_chunk(record + kRecordHeaderSize, rh.length, place, kRecordHeaderSize);
  const ChunkHeader& h = r.header;
  const auto codec = codec_of(h.compression);
  if (!codec)
    place.fail(0, "chunk compression '" + h.compression +
                      "' is not supported (ULC reads zstd, lz4 and uncompressed chunks)");
  const unsigned char* in = record + kRecordHeaderSize + h.records_pos;
  if (*codec == Codec::none) {
    if (h.records_size != h.uncompressed_size)
      place.fail(0, "uncompressed chunk holds " + std::to_string(h.records_size) +
                        " bytes of records, its header claims " +
                        std::to_string(h.uncompressed_size));
    r.data = in;
  } else {
    decompress(*codec, in, static_cast<std::size_t>(h.records_size), h.uncompressed_size, out,
               BlockPlace{file, offset});
    r.data = out.data();
  }
  r.size = h.uncompressed_size;
  if (h.uncompressed_crc != 0) {
    const std::uint32_t crc = crc32(r.data, static_cast<std::size_t>(r.size));
    if (crc != h.uncompressed_crc)
      place.fail(0, "chunk CRC mismatch: its uncompressed records give CRC " + hex32(crc) +
                        ", its header says " + hex32(h.uncompressed_crc) + " (corrupted data)");
  }
  return r;
}

/// Calls visit(slot, entries, count, record_offset) for the MessageIndex records after chunk
/// `c` whose channel slot `want(slot)` accepts. `buf` receives the MessageIndex records.
template <typename Want, typename Visit>
void for_each_message_index(const FileReader& file, const FileIndex& index, const ChunkRef& c,
                            std::vector<unsigned char>& buf, Want want, Visit visit) {
  bool any = false;
  for (const auto& [id, offset] : c.index_offsets) any = any || want(index.slot_of(id));
  if (!any) return;
  file.read_at(c.index_offset, c.index_length, buf, "MessageIndex records");
  const Place place{file.name(), c.index_offset};
  for (const auto& [id, offset] : c.index_offsets) {
    const std::int32_t slot = index.slot_of(id);
    if (!want(slot)) continue;
    const std::uint64_t pos = offset - c.index_offset;  // checked when the index was read
    if (c.index_length - pos < kRecordHeaderSize)
      place.fail(pos, "truncated MessageIndex record header");
    const RecordHeader rh = parse_record_header(buf.data() + pos);
    if (!is(rh.op, Op::message_index))
      place.fail(pos, "ChunkIndex points to a MessageIndex record here, found " + op_name(rh.op));
    if (rh.length > c.index_length - pos - kRecordHeaderSize)
      place.fail(pos, "MessageIndex record of " + std::to_string(rh.length) +
                          " bytes runs past the chunk's " + std::to_string(c.index_length) +
                          " bytes of message indexes");
    const MessageIndexRecord m = parse_message_index(buf.data() + pos + kRecordHeaderSize,
                                                     rh.length, place, pos + kRecordHeaderSize);
    if (m.channel_id != id)
      place.fail(pos, "MessageIndex record of channel " + std::to_string(m.channel_id) +
                          " where the ChunkIndex expects channel " + std::to_string(id));
    visit(slot, m.entries, m.count, c.index_offset + pos);
  }
}

/// Registers Schema and Channel records; a second record with an id already seen must agree.
class Declarations {
 public:
  explicit Declarations(FileIndex& index) : index_(index) {}

  void schema(const SchemaRecord& s, const Place& place, std::uint64_t pos) {
    if (s.id == 0) return;  // the specification: an id of zero is invalid, ignored
    const auto [it, added] = index_.schemas.emplace(s.id, s);
    if (!added && it->second.name != s.name)
      place.fail(pos, "Schema " + std::to_string(s.id) + " declared twice, as '" + it->second.name +
                          "' and as '" + s.name + "'");
  }

  void channel(const ChannelRecord& c, const Place& place, std::uint64_t pos) {
    std::int32_t& slot = index_.channel_slot[c.id];
    if (slot >= 0) {
      const ChannelInfo& old = index_.channels[static_cast<std::size_t>(slot)];
      if (old.topic != c.topic || old.encoding != c.message_encoding ||
          old.schema_id != c.schema_id)
        place.fail(pos, "Channel " + std::to_string(c.id) + " declared twice with different " +
                            "contents (topic '" + old.topic + "' and '" + c.topic + "')");
      return;
    }
    slot = static_cast<std::int32_t>(index_.channels.size());
    index_.channels.push_back(
        {c.id, c.schema_id, c.topic, c.message_encoding, place.offset_of(pos), 0});
  }

 private:
  FileIndex& index_;
};

/// Per-channel message counts and times while the file is being indexed.
struct ChannelTally {
  std::uint64_t count = 0;
  bool timed = false;
  std::int64_t first = 0;
  std::int64_t last = 0;

  void time(std::int64_t t) {
    first = timed ? std::min(first, t) : t;
    last = timed ? std::max(last, t) : t;
    timed = true;
  }
};

/// Opens the file: reads its summary or scans its data section, fills a FileIndex.
class IndexBuilder {
 public:
  IndexBuilder(const FileReader& file, FileIndex& index)
      : file_(file), index_(index), declare_(index), window_(file) {}

  void build() {
    check_leading_magic();
    const auto footer = read_tail();
    if (!footer)
      file_.fail(file_.size(),
                 "truncated MCAP file: no Footer and closing magic at its end (cut short, or a "
                 "recording that was never closed)");
    if (footer->summary_start != 0) {
      read_summary(*footer);
      walk(footer->summary_start, /*check_crc=*/false);
      check_indexed_chunks_seen();
    } else {
      index_.warnings.push_back(
          "no summary section (Footer summary_start is 0): messages indexed by a linear scan of "
          "the data section");
      walk(footer_offset_, /*check_crc=*/true);
    }
    build_topics();
    tally_topics();
  }

 private:
  // ----- the ends of the file ----------------------------------------------------------------

  void check_leading_magic() {
    if (file_.size() < kMagicSize)
      file_.fail(0, "not an MCAP file: " + std::to_string(file_.size()) +
                        " bytes, fewer than the 8-byte magic");
    unsigned char m[kMagicSize];
    file_.read_into(0, m, kMagicSize, "magic");
    if (std::memcmp(m, kMagic.data(), 5) != 0) file_.fail(0, "not an MCAP file: no magic");
    if (std::memcmp(m, kMagic.data(), kMagicSize) != 0)
      file_.fail(5, "unsupported MCAP major version '" + std::string(1, char(m[5])) +
                        "' (ULC reads version 0)");
  }

  /// The Footer when the file ends with Footer and magic; nullopt for a file cut short.
  std::optional<FooterRecord> read_tail() {
    constexpr std::uint64_t tail = kRecordHeaderSize + kFooterContentSize + kMagicSize;
    if (file_.size() < kMagicSize + tail) return std::nullopt;
    unsigned char t[tail];
    footer_offset_ = file_.size() - tail;
    file_.read_into(footer_offset_, t, tail, "Footer");
    const RecordHeader rh = parse_record_header(t);
    if (!is(rh.op, Op::footer) || rh.length != kFooterContentSize ||
        std::memcmp(t + tail - kMagicSize, kMagic.data(), kMagicSize) != 0)
      return std::nullopt;
    return parse_footer(t + kRecordHeaderSize);
  }

  // ----- the summary section -----------------------------------------------------------------

  void read_summary(const FooterRecord& footer) {
    const std::uint64_t start = footer.summary_start;
    if (start < kMagicSize || start > footer_offset_)
      file_.fail(footer_offset_, "Footer summary_start " + std::to_string(start) +
                                     " lies outside the file's records (the Footer is at byte " +
                                     std::to_string(footer_offset_) + ")");
    std::vector<unsigned char> s;
    // Summary and summary offset sections, then the Footer's opcode, length and two offsets: the
    // bytes summary_crc covers.
    file_.read_at(start, footer_offset_ - start + kRecordHeaderSize + 16, s, "summary section");
    if (footer.summary_crc != 0) {
      const std::uint32_t crc = crc32(s.data(), s.size());
      if (crc != footer.summary_crc)
        file_.fail(start, "summary CRC mismatch: the summary section gives CRC " + hex32(crc) +
                              ", the Footer says " + hex32(footer.summary_crc) +
                              " (corrupted data)");
    }
    const Place place{file_.name(), start};
    const std::uint64_t n = footer_offset_ - start;
    std::uint64_t pos = 0;
    while (pos < n) {
      if (n - pos < kRecordHeaderSize) place.fail(pos, "truncated record header in the summary");
      const RecordHeader rh = parse_record_header(s.data() + pos);
      if (rh.length > n - pos - kRecordHeaderSize)
        place.fail(pos, op_name(rh.op) + " record of " + std::to_string(rh.length) +
                            " bytes runs past the summary section's end at byte " +
                            std::to_string(footer_offset_));
      summary_record(rh, s.data() + pos + kRecordHeaderSize, place, pos + kRecordHeaderSize, start);
      pos += kRecordHeaderSize + rh.length;
    }
    std::sort(index_.chunks.begin(), index_.chunks.end(),
              [](const ChunkRef& a, const ChunkRef& b) { return a.offset < b.offset; });
    for (std::size_t k = 1; k < index_.chunks.size(); ++k)
      if (index_.chunks[k].offset == index_.chunks[k - 1].offset)
        file_.fail(start, "two ChunkIndex records describe the chunk at byte " +
                              std::to_string(index_.chunks[k].offset));
  }

  void summary_record(const RecordHeader& rh, const unsigned char* c, const Place& place,
                      std::uint64_t pos, std::uint64_t data_end) {
    switch (static_cast<Op>(rh.op)) {
      case Op::schema:
        return declare_.schema(parse_schema(c, rh.length, place, pos), place, pos);
      case Op::channel:
        return declare_.channel(parse_channel(c, rh.length, place, pos), place, pos);
      case Op::statistics:
        statistics_ = parse_statistics(c, rh.length, place, pos);
        return;
      case Op::chunk_index:
        return chunk_index(parse_chunk_index(c, rh.length, place, pos), place, pos, data_end);
      default:
        return;  // AttachmentIndex, MetadataIndex, SummaryOffset, unknown: not needed
    }
  }

  void chunk_index(const ChunkIndexRecord& x, const Place& place, std::uint64_t pos,
                   std::uint64_t data_end) {
    const auto codec = codec_of(x.compression);
    if (!codec)
      place.fail(pos, "chunk at byte " + std::to_string(x.chunk_start_offset) +
                          " uses compression '" + x.compression +
                          "', which is not supported (ULC reads zstd, lz4 and uncompressed)");
    const std::uint64_t first = kMagicSize;
    const bool inside =
        x.chunk_start_offset >= first && x.chunk_start_offset <= data_end &&
        x.chunk_length <= data_end - x.chunk_start_offset &&
        x.message_index_length <= data_end - x.chunk_start_offset - x.chunk_length &&
        x.chunk_length >= chunk_records_pos(x.compression) && x.compressed_size <= x.chunk_length;
    if (!inside)
      place.fail(
          pos, "ChunkIndex places a chunk of " + std::to_string(x.chunk_length) + " bytes (and " +
                   std::to_string(x.message_index_length) + " bytes of message indexes) at byte " +
                   std::to_string(x.chunk_start_offset) +
                   ", outside the data section that ends at byte " + std::to_string(data_end));
    if (x.message_index_offsets.empty()) return;  // not indexed: the walk lists its messages
    ChunkRef c;
    c.offset = x.chunk_start_offset;
    c.length = x.chunk_length;
    c.start_time = static_cast<std::int64_t>(x.message_start_time);
    c.end_time = static_cast<std::int64_t>(x.message_end_time);
    c.codec = *codec;
    c.compression = x.compression;
    c.compressed_size = x.compressed_size;
    c.uncompressed_size = x.uncompressed_size;
    c.index_offset = x.chunk_start_offset + x.chunk_length;
    c.index_length = x.message_index_length;
    c.index_offsets = x.message_index_offsets;
    c.indexed = true;
    for (const auto& [id, offset] : c.index_offsets)
      if (offset < c.index_offset || offset - c.index_offset >= c.index_length)
        place.fail(pos, "ChunkIndex puts the MessageIndex of channel " + std::to_string(id) +
                            " at byte " + std::to_string(offset) + ", outside the " +
                            std::to_string(c.index_length) + " bytes after the chunk");
    index_.chunks.push_back(std::move(c));
  }

  // ----- the data section --------------------------------------------------------------------

  /// Walks the records from the Header to DataEnd or `limit` (the summary or the Footer); a
  /// record running past `limit` is an error.
  void walk(std::uint64_t limit, bool check_crc) {
    std::uint64_t pos = kMagicSize;
    std::uint32_t crc = crc32(kMagic.data(), kMagicSize);
    for (bool first = true;; first = false) {
      if (pos == limit) return;
      const std::uint64_t left = limit - pos;
      if (left < kRecordHeaderSize) cut(pos, "a record header");
      const RecordHeader rh = parse_record_header(window_.get(pos, kRecordHeaderSize, "record"));
      if (rh.length > left - kRecordHeaderSize)
        file_.fail(pos, op_name(rh.op) + " record of " + std::to_string(rh.length) +
                            " bytes runs past the end of the data section at byte " +
                            std::to_string(limit));
      if (first && !is(rh.op, Op::header))
        file_.fail(pos, "the first record must be a Header, found " + op_name(rh.op));
      if (is(rh.op, Op::data_end)) return data_end(pos, rh.length, check_crc ? &crc : nullptr);
      data_record(pos, rh);
      if (check_crc) crc = crc_of(pos, kRecordHeaderSize + rh.length, crc);
      pos += kRecordHeaderSize + rh.length;
    }
  }

  [[noreturn]] void cut(std::uint64_t pos, const std::string& what) {
    file_.fail(pos, "truncated data section: " + what + " does not fit before its end");
  }

  void data_end(std::uint64_t pos, std::uint64_t length, const std::uint32_t* crc) {
    if (length < 4)
      file_.fail(pos, "truncated DataEnd record: " + std::to_string(length) + " bytes");
    const std::uint32_t claimed =
        io::load_le<std::uint32_t>(window_.get(pos + kRecordHeaderSize, 4, "DataEnd record"));
    if (crc && claimed != 0 && claimed != *crc)
      file_.fail(pos, "data section CRC mismatch: the data section gives CRC " + hex32(*crc) +
                          ", DataEnd says " + hex32(claimed) + " (corrupted data)");
  }

  std::uint32_t crc_of(std::uint64_t pos, std::uint64_t n, std::uint32_t crc) {
    while (n > 0) {
      const std::uint64_t step = std::min<std::uint64_t>(n, kWindowBytes);
      crc =
          crc32_update(crc, window_.get(pos, step, "data section"), static_cast<std::size_t>(step));
      pos += step;
      n -= step;
    }
    return crc;
  }

  void data_record(std::uint64_t pos, const RecordHeader& rh) {
    const Op op = static_cast<Op>(rh.op);
    if (op != Op::header && op != Op::schema && op != Op::channel && op != Op::message &&
        op != Op::chunk)
      return;  // MessageIndex (chunks are scanned whole), Attachment, Metadata, unknown
    if (op == Op::chunk && skip_indexed_chunk(pos, rh)) return;
    const unsigned char* c =
        window_.get(pos, kRecordHeaderSize + rh.length, "record") + kRecordHeaderSize;
    const Place place{file_.name(), pos};
    switch (op) {
      case Op::header:
        parse_header(c, rh.length, place, kRecordHeaderSize);
        return;
      case Op::schema:
        return declare_.schema(parse_schema(c, rh.length, place, kRecordHeaderSize), place,
                               kRecordHeaderSize);
      case Op::channel:
        return declare_.channel(parse_channel(c, rh.length, place, kRecordHeaderSize), place,
                                kRecordHeaderSize);
      case Op::message:
        return message(parse_message(c, rh.length, place, kRecordHeaderSize), pos, kLoose, place,
                       kRecordHeaderSize);
      default:
        return scan_chunk(c - kRecordHeaderSize, pos, kRecordHeaderSize + rh.length);
    }
  }

  /// True for a chunk that a ChunkIndex with message indexes describes: its messages are listed
  /// from those indexes, the walk jumps over it.
  bool skip_indexed_chunk(std::uint64_t pos, const RecordHeader& rh) {
    const auto it =
        std::lower_bound(index_.chunks.begin(), index_.chunks.end(), pos,
                         [](const ChunkRef& c, std::uint64_t offset) { return c.offset < offset; });
    if (it == index_.chunks.end() || it->offset != pos || !it->indexed) return false;
    if (it->length != kRecordHeaderSize + rh.length)
      file_.fail(pos, "Chunk record of " + std::to_string(kRecordHeaderSize + rh.length) +
                          " bytes, its ChunkIndex says " + std::to_string(it->length));
    it->seen = true;
    return true;
  }

  void scan_chunk(const unsigned char* record, std::uint64_t pos, std::uint64_t n) {
    const ChunkRecords r = open_chunk(record, n, pos, file_.name(), scratch_);
    ChunkRef c;
    c.offset = pos;
    c.length = n;
    c.start_time = static_cast<std::int64_t>(r.header.message_start_time);
    c.end_time = static_cast<std::int64_t>(r.header.message_end_time);
    c.codec = *codec_of(r.header.compression);
    c.compression = r.header.compression;
    c.compressed_size = r.header.records_size;
    c.uncompressed_size = r.header.uncompressed_size;
    c.index_offset = pos + n;
    const auto number = static_cast<std::uint32_t>(unindexed_.size());
    const Place place = c.codec == Codec::none
                            ? Place{file_.name(), pos + kRecordHeaderSize + r.header.records_pos}
                            : Place{file_.name(), pos, true};
    unindexed_.push_back(std::move(c));
    scan_chunk_records(r.data, r.size, number, place);
  }

  void scan_chunk_records(const unsigned char* r, std::uint64_t n, std::uint32_t chunk,
                          const Place& place) {
    std::uint64_t p = 0;
    while (p < n) {
      if (n - p < kRecordHeaderSize) place.fail(p, "truncated record header inside a chunk");
      const RecordHeader rh = parse_record_header(r + p);
      if (rh.length > n - p - kRecordHeaderSize)
        place.fail(p, op_name(rh.op) + " record of " + std::to_string(rh.length) +
                          " bytes runs past the end of its chunk");
      const unsigned char* c = r + p + kRecordHeaderSize;
      const std::uint64_t at = p + kRecordHeaderSize;
      if (is(rh.op, Op::schema)) declare_.schema(parse_schema(c, rh.length, place, at), place, at);
      if (is(rh.op, Op::channel))
        declare_.channel(parse_channel(c, rh.length, place, at), place, at);
      if (is(rh.op, Op::message))
        message(parse_message(c, rh.length, place, at), p, chunk, place, at);
      p += kRecordHeaderSize + rh.length;
    }
  }

  void message(const MessageHeader& m, std::uint64_t pos, std::uint32_t chunk, const Place& place,
               std::uint64_t at) {
    const std::int32_t slot = index_.slot_of(m.channel_id);
    if (slot < 0)
      place.fail(at, "Message on channel " + std::to_string(m.channel_id) +
                         ", which no earlier Channel record declares");
    index_.scanned.push_back(
        {static_cast<std::int64_t>(m.log_time), pos, chunk, static_cast<std::uint32_t>(slot)});
  }

  /// Every indexed chunk must be where the walk found a Chunk record; chunks the walk scanned go
  /// after the indexed ones (their entries are renumbered).
  void check_indexed_chunks_seen() {
    for (const ChunkRef& c : index_.chunks)
      if (!c.seen)
        file_.fail(c.offset, "a ChunkIndex points here, but no Chunk record starts at this byte");
    for (const ChunkRef& c : index_.chunks)
      for (const auto& [id, offset] : c.index_offsets)
        if (index_.slot_of(id) < 0)
          file_.fail(offset, "MessageIndex of channel " + std::to_string(id) +
                                 ", which no Channel record of the summary declares");
  }

  // ----- topics --------------------------------------------------------------------------------

  void build_topics() {
    const auto base = static_cast<std::uint32_t>(index_.chunks.size());
    for (Entry& e : index_.scanned)
      if (e.chunk != kLoose) e.chunk += base;
    for (ChunkRef& c : unindexed_) index_.chunks.push_back(std::move(c));
    std::map<std::string, std::vector<std::size_t>> by_name;
    for (std::size_t s = 0; s < index_.channels.size(); ++s)
      by_name[index_.channels[s].topic].push_back(s);
    for (const auto& [name, slots] : by_name) add_topic(name, slots);
  }

  void add_topic(const std::string& name, const std::vector<std::size_t>& slots) {
    const ChannelInfo& first = index_.channels[slots.front()];
    TopicInfo t;
    t.name = name;
    t.type = schema_name(first);
    t.serialization = first.encoding == "ros1" ? Serialization::ros1 : Serialization::cdr;
    t.connections = slots.size();
    std::string problem;
    if (first.encoding != "cdr" && first.encoding != "ros1")
      problem = "message encoding '" + first.encoding + "' of topic '" + name +
                "' is not supported (ULC decodes cdr and ros1)";
    for (std::size_t s : slots) {
      index_.channels[s].topic_index = index_.topics.size();
      schema_name(index_.channels[s]);
      if (problem.empty() && index_.channels[s].encoding != first.encoding)
        problem = "the channels of topic '" + name + "' use different message encodings ('" +
                  first.encoding + "' and '" + index_.channels[s].encoding + "')";
    }
    index_.topics.push_back(t);
    index_.topic_problem.push_back(problem);
    index_.topic_offset.push_back(first.record_offset);
  }

  std::string schema_name(const ChannelInfo& c) const {
    if (c.schema_id == 0) return "";
    const auto it = index_.schemas.find(c.schema_id);
    if (it == index_.schemas.end())
      file_.fail(c.record_offset, "Channel " + std::to_string(c.id) + " refers to Schema " +
                                      std::to_string(c.schema_id) +
                                      ", which no Schema record declares");
    return it->second.name;
  }

  /// Message counts and first / last times per topic.
  void tally_topics() {
    std::vector<ChannelTally> tally(index_.channels.size());
    for (const Entry& e : index_.scanned) {
      ++tally[e.topic].count;
      tally[e.topic].time(e.time);
    }
    const bool counted = statistics_ && !statistics_->channel_message_counts.empty();
    if (counted) {
      for (auto& t : tally) t.count = 0;
      for (const auto& [id, count] : statistics_->channel_message_counts)
        if (index_.slot_of(id) >= 0)
          tally[static_cast<std::size_t>(index_.slot_of(id))].count = count;
      search_first_last(tally);
    } else {
      count_from_indexes(tally);
    }
    for (Entry& e : index_.scanned)
      e.topic = static_cast<std::uint32_t>(index_.channels[e.topic].topic_index);
    std::vector<ChannelTally> per_topic(index_.topics.size());
    for (std::size_t s = 0; s < tally.size(); ++s) {
      ChannelTally& t = per_topic[index_.channels[s].topic_index];
      t.count += tally[s].count;
      if (tally[s].timed) {
        t.time(tally[s].first);
        t.time(tally[s].last);
      }
    }
    for (std::size_t k = 0; k < per_topic.size(); ++k) {
      index_.topics[k].message_count = per_topic[k].count;
      index_.topics[k].first_time_ns = per_topic[k].first;
      index_.topics[k].last_time_ns = per_topic[k].last;
    }
  }

  /// Without per-channel statistics: every chunk's MessageIndex records give counts and times.
  void count_from_indexes(std::vector<ChannelTally>& tally) {
    for (const ChunkRef& c : index_.chunks) {
      if (!c.indexed) continue;
      for_each_message_index(
          file_, index_, c, scratch_, [](std::int32_t slot) { return slot >= 0; },
          [&](std::int32_t slot, const unsigned char* e, std::uint64_t n, std::uint64_t) {
            ChannelTally& t = tally[static_cast<std::size_t>(slot)];
            t.count += n;
            for (std::uint64_t k = 0; k < n; ++k)
              t.time(
                  static_cast<std::int64_t>(io::load_le<std::uint64_t>(e + k * kIndexEntrySize)));
          });
    }
  }

  /// With counts from the statistics: the first (last) time of a channel is in one of the chunks
  /// whose start (end) time is below (above) the best found so far; chunks sorted by start time
  /// (descending end time) stop being read as soon as none can do better.
  void search_first_last(std::vector<ChannelTally>& tally) {
    std::vector<const ChunkRef*> order;
    for (const ChunkRef& c : index_.chunks)
      if (c.indexed) order.push_back(&c);
    std::sort(order.begin(), order.end(),
              [](const ChunkRef* a, const ChunkRef* b) { return a->start_time < b->start_time; });
    std::vector<ChannelTally> best(tally.size());
    for (const ChunkRef* c : order)
      read_times_if(*c, best,
                    [&](const ChannelTally& b) { return !b.timed || c->start_time < b.first; });
    std::sort(order.begin(), order.end(),
              [](const ChunkRef* a, const ChunkRef* b) { return a->end_time > b->end_time; });
    for (const ChunkRef* c : order)
      read_times_if(*c, best,
                    [&](const ChannelTally& b) { return !b.timed || c->end_time > b.last; });
    for (std::size_t s = 0; s < tally.size(); ++s)
      if (best[s].timed) {
        tally[s].time(best[s].first);
        tally[s].time(best[s].last);
      }
  }

  template <typename Need>
  void read_times_if(const ChunkRef& c, std::vector<ChannelTally>& best, Need need) {
    for_each_message_index(
        file_, index_, c, scratch_,
        [&](std::int32_t slot) { return slot >= 0 && need(best[static_cast<std::size_t>(slot)]); },
        [&](std::int32_t slot, const unsigned char* e, std::uint64_t n, std::uint64_t) {
          for (std::uint64_t k = 0; k < n; ++k)
            best[static_cast<std::size_t>(slot)].time(
                static_cast<std::int64_t>(io::load_le<std::uint64_t>(e + k * kIndexEntrySize)));
        });
  }

  const FileReader& file_;
  FileIndex& index_;
  Declarations declare_;
  ReadWindow window_;
  std::uint64_t footer_offset_ = 0;
  std::optional<StatisticsRecord> statistics_;
  std::vector<ChunkRef> unindexed_;  ///< chunks the walk scanned
  std::vector<unsigned char> scratch_;
};

// ----- reading ---------------------------------------------------------------------------------

/// The selected messages in (time, file position) order.
inline std::vector<Entry> collect_entries(const FileReader& file, const FileIndex& index,
                                          const std::vector<std::size_t>& selected,
                                          const TimeWindow& window) {
  std::vector<char> topic_wanted(index.topics.size(), 0);
  for (std::size_t t : selected) {
    if (t >= index.topics.size())
      throw std::out_of_range("MCAP cursor: topic index " + std::to_string(t) + " of " +
                              std::to_string(index.topics.size()));
    if (!index.topic_problem[t].empty()) file.fail(index.topic_offset[t], index.topic_problem[t]);
    topic_wanted[t] = 1;
  }
  std::vector<Entry> entries;
  for (const Entry& e : index.scanned)
    if (topic_wanted[e.topic] && window.contains(e.time)) entries.push_back(e);
  std::vector<unsigned char> buf;
  const auto wanted = [&](std::int32_t slot) {
    return slot >= 0 && topic_wanted[index.channels[static_cast<std::size_t>(slot)].topic_index];
  };
  for (std::size_t k = 0; k < index.chunks.size(); ++k) {
    const ChunkRef& c = index.chunks[k];
    if (!c.indexed || c.end_time < window.begin_ns || c.start_time >= window.end_ns) continue;
    for_each_message_index(
        file, index, c, buf, wanted,
        [&](std::int32_t slot, const unsigned char* e, std::uint64_t n, std::uint64_t at) {
          const auto topic = static_cast<std::uint32_t>(
              index.channels[static_cast<std::size_t>(slot)].topic_index);
          for (std::uint64_t i = 0; i < n; ++i, e += kIndexEntrySize) {
            const auto t = static_cast<std::int64_t>(io::load_le<std::uint64_t>(e));
            const std::uint64_t pos = io::load_le<std::uint64_t>(e + 8);
            if (pos > c.uncompressed_size ||
                c.uncompressed_size - pos < kRecordHeaderSize + kMessageFixedSize)
              file.fail(at, "MessageIndex entry points to byte " + std::to_string(pos) +
                                " of a chunk whose records hold " +
                                std::to_string(c.uncompressed_size) + " bytes");
            if (window.contains(t))
              entries.push_back({t, pos, static_cast<std::uint32_t>(k), topic});
          }
        });
  }
  const auto container = [&](const Entry& e) {
    return e.chunk == kLoose ? e.pos : index.chunks[e.chunk].offset;
  };
  const auto before = [&](const Entry& a, const Entry& b) {
    if (a.time != b.time) return a.time < b.time;
    const std::uint64_t ca = container(a), cb = container(b);
    return ca != cb ? ca < cb : a.pos < b.pos;
  };
  if (!std::is_sorted(entries.begin(), entries.end(), before))
    std::sort(entries.begin(), entries.end(), before);
  return entries;
}

class Cursor : public MessageCursor {
 public:
  Cursor(const FileReader& file, const FileIndex& index, std::vector<Entry> entries)
      : file_(file), index_(index), entries_(std::move(entries)), loose_(file) {
    last_use_.assign(index.chunks.size(), 0);
    for (std::size_t i = 0; i < entries_.size(); ++i)
      if (entries_[i].chunk != kLoose) last_use_[entries_[i].chunk] = i;
    slots_.reserve(kMaxCachedChunks);
  }

  bool next(MessageView& out) override {
    if (next_ == entries_.size()) return false;
    const std::size_t i = next_++;
    const Entry& e = entries_[i];
    if (e.chunk == kLoose) {
      read_loose(e, out);
    } else {
      Slot& s = slot_for(e.chunk);
      read_chunked(e, s, out);
      if (last_use_[e.chunk] == i) s.chunk = kLoose;  // free for the next chunk
    }
    return true;
  }

 private:
  struct Slot {
    std::uint32_t chunk = kLoose;  ///< kLoose: free
    std::vector<unsigned char> data;
    const unsigned char* records = nullptr;
    std::uint64_t size = 0;
    std::uint64_t records_offset = 0;  ///< file offset of the records (uncompressed chunks)
    std::uint64_t used = 0;
  };

  Slot& slot_for(std::uint32_t chunk) {
    ++clock_;
    for (Slot& s : slots_)
      if (s.chunk == chunk) {
        s.used = clock_;
        return s;
      }
    Slot* pick = nullptr;
    for (Slot& s : slots_)
      if (s.chunk == kLoose) pick = &s;
    if (!pick && slots_.size() < kMaxCachedChunks) pick = &slots_.emplace_back();
    if (!pick)
      pick = &*std::min_element(slots_.begin(), slots_.end(),
                                [](const Slot& a, const Slot& b) { return a.used < b.used; });
    pick->chunk = kLoose;
    load(chunk, *pick);
    pick->chunk = chunk;
    pick->used = clock_;
    return *pick;
  }

  void load(std::uint32_t chunk, Slot& s) {
    const ChunkRef& c = index_.chunks[chunk];
    std::vector<unsigned char>& record = c.codec == Codec::none ? s.data : raw_;
    file_.read_at(c.offset, c.length, record, "Chunk record");
    const ChunkRecords r = open_chunk(record.data(), c.length, c.offset, file_.name(), s.data);
    if (r.header.compression != c.compression || r.header.records_size != c.compressed_size ||
        r.header.uncompressed_size != c.uncompressed_size)
      file_.fail(c.offset, "Chunk record (compression '" + r.header.compression + "', " +
                               std::to_string(r.header.records_size) + " -> " +
                               std::to_string(r.header.uncompressed_size) +
                               " bytes) disagrees with its ChunkIndex ('" + c.compression + "', " +
                               std::to_string(c.compressed_size) + " -> " +
                               std::to_string(c.uncompressed_size) + " bytes)");
    s.records = r.data;
    s.size = r.size;
    s.records_offset = c.offset + kRecordHeaderSize + r.header.records_pos;
  }

  void read_chunked(const Entry& e, const Slot& s, MessageView& out) const {
    const ChunkRef& c = index_.chunks[e.chunk];
    const Place place = c.codec == Codec::none ? Place{file_.name(), s.records_offset}
                                               : Place{file_.name(), c.offset, true};
    if (e.pos > s.size || s.size - e.pos < kRecordHeaderSize)
      place.fail(e.pos, "message index points past the chunk's records");
    const RecordHeader rh = parse_record_header(s.records + e.pos);
    if (!is(rh.op, Op::message))
      place.fail(e.pos, "message index points to a " + op_name(rh.op) + " record, not a Message");
    if (rh.length > s.size - e.pos - kRecordHeaderSize)
      place.fail(e.pos, "Message record of " + std::to_string(rh.length) +
                            " bytes runs past the end of its chunk");
    const unsigned char* content = s.records + e.pos + kRecordHeaderSize;
    const MessageHeader m = parse_message(content, rh.length, place, e.pos + kRecordHeaderSize);
    check_matches(m, e, place, e.pos);
    fill(out, e, content, m, place.offset_of(e.pos));
  }

  void read_loose(const Entry& e, MessageView& out) {
    const Place place{file_.name(), e.pos};
    const RecordHeader rh = parse_record_header(loose_.get(e.pos, kRecordHeaderSize, "Message"));
    if (!is(rh.op, Op::message))
      place.fail(0, "expected a Message record, found " + op_name(rh.op));
    const unsigned char* content =
        loose_.get(e.pos, kRecordHeaderSize + rh.length, "Message record") + kRecordHeaderSize;
    const MessageHeader m = parse_message(content, rh.length, place, kRecordHeaderSize);
    check_matches(m, e, place, 0);
    fill(out, e, content, m, e.pos);
  }

  void check_matches(const MessageHeader& m, const Entry& e, const Place& place,
                     std::uint64_t pos) const {
    const std::int32_t slot = index_.slot_of(m.channel_id);
    if (slot < 0 || index_.channels[static_cast<std::size_t>(slot)].topic_index != e.topic)
      place.fail(pos, "Message of channel " + std::to_string(m.channel_id) +
                          " where the message index expects topic '" + index_.topics[e.topic].name +
                          "'");
    if (static_cast<std::int64_t>(m.log_time) != e.time)
      place.fail(pos, "Message log_time " + std::to_string(m.log_time) +
                          " differs from its message index's " + std::to_string(e.time));
  }

  void fill(MessageView& out, const Entry& e, const unsigned char* content, const MessageHeader& m,
            std::uint64_t offset) const {
    out.topic = e.topic;
    out.time_ns = e.time;
    out.data = content + kMessageFixedSize;
    out.size = static_cast<std::size_t>(m.data_size);
    out.file = &file_.name();
    out.offset = offset;
  }

  const FileReader& file_;
  const FileIndex& index_;
  std::vector<Entry> entries_;
  std::size_t next_ = 0;
  std::vector<std::size_t> last_use_;  ///< per chunk: its last entry
  std::vector<Slot> slots_;
  std::vector<unsigned char> raw_;  ///< a compressed Chunk record being decompressed
  ReadWindow loose_;
  std::uint64_t clock_ = 0;
};

}  // namespace mcap

class McapReader : public MessageSource {
 public:
  explicit McapReader(const std::filesystem::path& file) : file_(file) {
    mcap::IndexBuilder(file_, index_).build();
  }

  const std::vector<TopicInfo>& topics() const override { return index_.topics; }
  std::vector<std::string> warnings() const override { return index_.warnings; }

  /// Throws IoError when a selected topic's message encoding is not cdr or ros1.
  std::unique_ptr<MessageCursor> cursor(const std::vector<std::size_t>& selected,
                                        TimeWindow window) const override {
    return std::make_unique<mcap::Cursor>(file_, index_,
                                          mcap::collect_entries(file_, index_, selected, window));
  }

  const std::string& file() const { return file_.name(); }

 private:
  FileReader file_;
  mcap::FileIndex index_;
};

}  // namespace ulc::bags
