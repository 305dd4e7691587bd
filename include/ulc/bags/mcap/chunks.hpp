// Reading an MCAP file's records: a read-ahead window over the data section, a Chunk record
// opened (decompressed, its CRC checked), and the MessageIndex records that follow a chunk.

#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/mcap/file_index.hpp"
#include "ulc/bags/mcap_records.hpp"

namespace ulc::bags::mcap {

/// Read-ahead of the data-section walk and of messages outside chunks.
constexpr std::size_t kWindowBytes = std::size_t{1} << 20;

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

}  // namespace ulc::bags::mcap
