// The data section of an MCAP file walked record by record (mcap_reader.hpp, "Opening"): the
// chunks a ChunkIndex lists are jumped over and marked seen; every other chunk is decompressed
// once and its messages listed, as are the messages outside chunks.

#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/mcap/chunks.hpp"
#include "ulc/bags/mcap/file_index.hpp"
#include "ulc/bags/mcap_records.hpp"
#include "ulc/io/endian.hpp"

namespace ulc::bags::mcap {

/// Walks a data section into a FileIndex: index.scanned receives the messages it found (their
/// chunk numbered among the unindexed chunks), take_unindexed() the chunks it scanned.
class DataWalk {
 public:
  DataWalk(const FileReader& file, FileIndex& index)
      : file_(file), index_(index), declare_(index), window_(file) {}

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

  std::vector<ChunkRef> take_unindexed() { return std::move(unindexed_); }

 private:
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

  const FileReader& file_;
  FileIndex& index_;
  Declarations declare_;
  ReadWindow window_;
  std::vector<ChunkRef> unindexed_;  ///< chunks the walk scanned
  std::vector<unsigned char> scratch_;
};

}  // namespace ulc::bags::mcap
