// The summary section of an MCAP file: its Schema, Channel, Statistics and ChunkIndex records,
// checked against the Footer's summary_crc when nonzero (mcap_reader.hpp, "Opening").

#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/mcap/file_index.hpp"
#include "ulc/bags/mcap_records.hpp"

namespace ulc::bags::mcap {

/// Reads the summary section into a FileIndex: chunks sorted by offset, channels and schemas
/// declared; returns the Statistics record when there is one.
class SummaryReader {
 public:
  SummaryReader(const FileReader& file, FileIndex& index, std::uint64_t footer_offset)
      : file_(file), index_(index), declare_(index), footer_offset_(footer_offset) {}

  std::optional<StatisticsRecord> read(const FooterRecord& footer) {
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
    return statistics_;
  }

 private:
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

  const FileReader& file_;
  FileIndex& index_;
  Declarations declare_;
  const std::uint64_t footer_offset_;
  std::optional<StatisticsRecord> statistics_;
};

}  // namespace ulc::bags::mcap
