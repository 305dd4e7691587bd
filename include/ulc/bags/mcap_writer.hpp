// McapWriter: writes an MCAP file (https://mcap.dev/spec) as rosbag2 and the reference writers
// do, for the tests, the benchmarks and conversions.
//
//   <magic> Header
//   chunked:   Chunk (Schema, Channel, Message records; compressed or not), MessageIndex per
//              channel of the chunk, ... ; not chunked: Schema, Channel, Message records
//   DataEnd (data_section_crc: CRC-32 of every byte before it, magic included)
//   write_summary: Schema, Channel, Statistics, ChunkIndex records, then one SummaryOffset per
//                  group
//   Footer (summary_start 0 without summary; summary_crc over the summary and the Footer's
//           opcode, length and offsets) <magic>
//
// Chunk.uncompressed_crc is filled in. Streams to disk: memory holds the open chunk (closed once
// it reaches chunk_bytes, so a bigger message makes one bigger chunk) and small per-chunk
// indexes. Channel and schema ids start at 1.
#pragma once

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/mcap_records.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

struct McapWriteOptions {
  Codec compression = Codec::none;  ///< none, zstd or lz4
  std::size_t chunk_bytes = 4 * 1024 * 1024;
  bool chunked = true;
  bool write_summary = true;
  std::string profile = "ros2";
};

class McapWriter {
 public:
  explicit McapWriter(const std::filesystem::path& file, McapWriteOptions options = {})
      : name_(file.string()), options_(std::move(options)) {
    if (options_.compression == Codec::bz2)
      throw std::invalid_argument("MCAP chunks are compressed with zstd or lz4, not bz2");
    out_ = std::fopen(name_.c_str(), "wb");
    if (!out_) throw io::IoError(name_, "", std::string("cannot create: ") + std::strerror(errno));
    std::setvbuf(out_, nullptr, _IOFBF, 1 << 20);
    emit(mcap::kMagic.data(), mcap::kMagicSize);
    std::vector<unsigned char> header;
    mcap::put_string(header, options_.profile);
    mcap::put_string(header, "ulc");
    emit_record(mcap::Op::header, header);
  }

  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  ~McapWriter() {
    try {
      close();
    } catch (...) {
      // A destructor must not throw; call close() to see write errors.
    }
  }

  /// `encoding`: "ros2msg" or "ros1msg"; `data`: the message definition.
  std::uint16_t add_schema(const std::string& name, const std::string& encoding,
                           const std::string& data) {
    check_open();
    if (schemas_.size() >= 65535) throw std::length_error("MCAP: more than 65535 schemas");
    const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
    std::vector<unsigned char> r;
    mcap::put_u16(r, id);
    mcap::put_string(r, name);
    mcap::put_string(r, encoding);
    mcap::put_string(r, data);
    schemas_.push_back(r);
    declare(mcap::Op::schema, r);
    return id;
  }

  /// `schema_id` from add_schema (0: no schema); `message_encoding`: "cdr" or "ros1".
  std::uint16_t add_channel(const std::string& topic, std::uint16_t schema_id,
                            const std::string& message_encoding) {
    check_open();
    if (schema_id > schemas_.size())
      throw std::invalid_argument("MCAP: schema " + std::to_string(schema_id) + " not added");
    if (channels_.size() >= 65535) throw std::length_error("MCAP: more than 65535 channels");
    const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
    std::vector<unsigned char> r;
    mcap::put_u16(r, id);
    mcap::put_u16(r, schema_id);
    mcap::put_string(r, topic);
    mcap::put_string(r, message_encoding);
    mcap::put_u32(r, 0);  // metadata: an empty map
    channels_.push_back(r);
    channel_counts_.push_back(0);
    chunk_index_.emplace_back();
    declare(mcap::Op::channel, r);
    return id;
  }

  void write(std::uint16_t channel, std::int64_t log_time_ns, std::int64_t publish_time_ns,
             const unsigned char* data, std::size_t size) {
    check_open();
    if (channel == 0 || channel > channels_.size())
      throw std::invalid_argument("MCAP: channel " + std::to_string(channel) + " not added");
    const auto log_time = static_cast<std::uint64_t>(log_time_ns);
    const std::uint32_t sequence = static_cast<std::uint32_t>(channel_counts_[channel - 1]++);
    count_message(log_time);
    std::vector<unsigned char>& sink = options_.chunked ? chunk_ : record_;
    if (!options_.chunked) record_.clear();
    const std::uint64_t at = sink.size();
    mcap::put_record_header(sink, mcap::Op::message, mcap::kMessageFixedSize + size);
    mcap::put_u16(sink, channel);
    mcap::put_u32(sink, sequence);
    mcap::put_u64(sink, log_time);
    mcap::put_u64(sink, static_cast<std::uint64_t>(publish_time_ns));
    sink.insert(sink.end(), data, data + size);
    if (!options_.chunked) return emit(record_.data(), record_.size());
    chunk_index_[channel - 1].emplace_back(log_time, at);
    chunk_start_ = chunk_messages_ == 0 ? log_time : std::min(chunk_start_, log_time);
    chunk_end_ = chunk_messages_ == 0 ? log_time : std::max(chunk_end_, log_time);
    ++chunk_messages_;
    if (chunk_.size() >= options_.chunk_bytes) flush_chunk();
  }

  /// Writes the last chunk, DataEnd, the summary and the Footer. Further calls do nothing.
  void close() {
    if (!out_) return;
    std::FILE* f = out_;
    try {
      flush_chunk();
      std::vector<unsigned char> end;
      mcap::put_u32(end, data_crc_);
      crc_ = Crc::none;
      emit_record(mcap::Op::data_end, end);
      const std::uint64_t summary_start = options_.write_summary ? position_ : 0;
      const std::uint64_t offsets_start = options_.write_summary ? write_summary() : 0;
      std::vector<unsigned char> footer;
      mcap::put_record_header(footer, mcap::Op::footer, mcap::kFooterContentSize);
      mcap::put_u64(footer, summary_start);
      mcap::put_u64(footer, offsets_start);
      emit(footer.data(), footer.size());
      std::vector<unsigned char> tail;
      mcap::put_u32(tail, options_.write_summary ? summary_crc_ : 0);
      crc_ = Crc::none;
      tail.insert(tail.end(), mcap::kMagic.begin(), mcap::kMagic.end());
      emit(tail.data(), tail.size());
    } catch (...) {
      out_ = nullptr;
      std::fclose(f);
      throw;
    }
    out_ = nullptr;
    if (std::fclose(f) != 0)
      throw io::IoError(name_, "", std::string("cannot finish writing: ") + std::strerror(errno));
  }

 private:
  enum class Crc { none, data, summary };

  void check_open() const {
    if (!out_) throw std::logic_error("McapWriter: " + name_ + " is already closed");
  }

  void emit(const unsigned char* p, std::size_t n) {
    if (n > 0 && std::fwrite(p, 1, n, out_) != n)
      throw io::IoError(name_, io::at_byte(static_cast<std::size_t>(position_)),
                        std::string("write failed: ") + std::strerror(errno));
    if (crc_ == Crc::data) data_crc_ = mcap::crc32_update(data_crc_, p, n);
    if (crc_ == Crc::summary) summary_crc_ = mcap::crc32_update(summary_crc_, p, n);
    position_ += n;
  }

  void emit_record(mcap::Op op, const std::vector<unsigned char>& content) {
    std::vector<unsigned char> h;
    mcap::put_record_header(h, op, content.size());
    emit(h.data(), h.size());
    emit(content.data(), content.size());
  }

  /// Schema and Channel records go into the open chunk (chunked) or straight to the file.
  void declare(mcap::Op op, const std::vector<unsigned char>& content) {
    if (!options_.chunked) return emit_record(op, content);
    mcap::put_record_header(chunk_, op, content.size());
    chunk_.insert(chunk_.end(), content.begin(), content.end());
  }

  void count_message(std::uint64_t log_time) {
    start_time_ = message_count_ == 0 ? log_time : std::min(start_time_, log_time);
    end_time_ = message_count_ == 0 ? log_time : std::max(end_time_, log_time);
    ++message_count_;
  }

  /// Chunk record, then one MessageIndex record per channel of the chunk.
  void flush_chunk() {
    if (chunk_.empty()) return;
    const std::uint32_t crc = mcap::crc32(chunk_.data(), chunk_.size());
    std::vector<unsigned char> packed;
    if (options_.compression != Codec::none)
      packed = compress(options_.compression, chunk_.data(), chunk_.size());
    const std::vector<unsigned char>& records =
        options_.compression == Codec::none ? chunk_ : packed;
    const std::string compression = mcap::compression_name(options_.compression);
    ChunkIndex x;
    x.start = chunk_messages_ ? chunk_start_ : 0;
    x.end = chunk_messages_ ? chunk_end_ : 0;
    x.offset = position_;
    x.compression = compression;
    x.compressed_size = records.size();
    x.uncompressed_size = chunk_.size();
    std::vector<unsigned char> h;
    mcap::put_record_header(h, mcap::Op::chunk,
                            8 + 8 + 8 + 4 + 4 + compression.size() + 8 + records.size());
    mcap::put_u64(h, x.start);
    mcap::put_u64(h, x.end);
    mcap::put_u64(h, chunk_.size());
    mcap::put_u32(h, crc);
    mcap::put_string(h, compression);
    mcap::put_u64(h, records.size());
    emit(h.data(), h.size());
    emit(records.data(), records.size());
    x.length = position_ - x.offset;
    write_message_indexes(x);
    chunk_indexes_.push_back(std::move(x));
    chunk_.clear();
    chunk_messages_ = 0;
  }

  struct ChunkIndex {
    std::uint64_t start = 0, end = 0, offset = 0, length = 0;
    std::vector<std::pair<std::uint16_t, std::uint64_t>> index_offsets;
    std::uint64_t index_length = 0;
    std::string compression;
    std::uint64_t compressed_size = 0, uncompressed_size = 0;
  };

  void write_message_indexes(ChunkIndex& x) {
    const std::uint64_t start = position_;
    for (std::size_t c = 0; c < chunk_index_.size(); ++c) {
      auto& entries = chunk_index_[c];
      if (entries.empty()) continue;
      x.index_offsets.emplace_back(static_cast<std::uint16_t>(c + 1), position_);
      std::vector<unsigned char> r;
      mcap::put_u16(r, static_cast<std::uint16_t>(c + 1));
      mcap::put_u32(r, static_cast<std::uint32_t>(entries.size() * mcap::kIndexEntrySize));
      for (const auto& [time, offset] : entries) {
        mcap::put_u64(r, time);
        mcap::put_u64(r, offset);
      }
      emit_record(mcap::Op::message_index, r);
      entries.clear();
    }
    x.index_length = position_ - start;
  }

  /// The summary section and its SummaryOffset records; returns summary_offset_start.
  std::uint64_t write_summary() {
    crc_ = Crc::summary;
    std::vector<std::pair<mcap::Op, std::pair<std::uint64_t, std::uint64_t>>> groups;
    const auto group = [&](mcap::Op op, auto&& write_records) {
      const std::uint64_t start = position_;
      write_records();
      if (position_ != start) groups.push_back({op, {start, position_ - start}});
    };
    group(mcap::Op::schema, [&] {
      for (const auto& s : schemas_) emit_record(mcap::Op::schema, s);
    });
    group(mcap::Op::channel, [&] {
      for (const auto& c : channels_) emit_record(mcap::Op::channel, c);
    });
    group(mcap::Op::statistics, [&] { emit_record(mcap::Op::statistics, statistics()); });
    group(mcap::Op::chunk_index, [&] {
      for (const auto& x : chunk_indexes_) emit_record(mcap::Op::chunk_index, chunk_index(x));
    });
    const std::uint64_t offsets_start = position_;
    for (const auto& [op, range] : groups) {
      std::vector<unsigned char> r;
      mcap::put_u8(r, static_cast<std::uint8_t>(op));
      mcap::put_u64(r, range.first);
      mcap::put_u64(r, range.second);
      emit_record(mcap::Op::summary_offset, r);
    }
    return offsets_start;
  }

  std::vector<unsigned char> statistics() const {
    std::vector<unsigned char> r;
    mcap::put_u64(r, message_count_);
    mcap::put_u16(r, static_cast<std::uint16_t>(schemas_.size()));
    mcap::put_u32(r, static_cast<std::uint32_t>(channels_.size()));
    mcap::put_u32(r, 0);  // attachments
    mcap::put_u32(r, 0);  // metadata
    mcap::put_u32(r, static_cast<std::uint32_t>(chunk_indexes_.size()));
    mcap::put_u64(r, message_count_ ? start_time_ : 0);
    mcap::put_u64(r, message_count_ ? end_time_ : 0);
    mcap::put_u32(r, static_cast<std::uint32_t>(channel_counts_.size() * 10));
    for (std::size_t c = 0; c < channel_counts_.size(); ++c) {
      mcap::put_u16(r, static_cast<std::uint16_t>(c + 1));
      mcap::put_u64(r, channel_counts_[c]);
    }
    return r;
  }

  static std::vector<unsigned char> chunk_index(const ChunkIndex& x) {
    std::vector<unsigned char> r;
    mcap::put_u64(r, x.start);
    mcap::put_u64(r, x.end);
    mcap::put_u64(r, x.offset);
    mcap::put_u64(r, x.length);
    mcap::put_u32(r, static_cast<std::uint32_t>(x.index_offsets.size() * 10));
    for (const auto& [channel, offset] : x.index_offsets) {
      mcap::put_u16(r, channel);
      mcap::put_u64(r, offset);
    }
    mcap::put_u64(r, x.index_length);
    mcap::put_string(r, x.compression);
    mcap::put_u64(r, x.compressed_size);
    mcap::put_u64(r, x.uncompressed_size);
    return r;
  }

  std::string name_;
  McapWriteOptions options_;
  std::FILE* out_ = nullptr;
  std::uint64_t position_ = 0;
  Crc crc_ = Crc::data;
  std::uint32_t data_crc_ = 0;
  std::uint32_t summary_crc_ = 0;

  std::vector<std::vector<unsigned char>> schemas_;   ///< Schema record contents
  std::vector<std::vector<unsigned char>> channels_;  ///< Channel record contents
  std::vector<std::uint64_t> channel_counts_;
  std::uint64_t message_count_ = 0;
  std::uint64_t start_time_ = 0, end_time_ = 0;

  std::vector<unsigned char> chunk_;   ///< records of the open chunk
  std::vector<unsigned char> record_;  ///< one Message record (not chunked)
  std::vector<std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;  ///< per channel
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0, chunk_messages_ = 0;
  std::vector<ChunkIndex> chunk_indexes_;
};

}  // namespace ulc::bags
