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
// offset for compressed chunks; time_ns = log_time.//
// The parts: mcap/file_index.hpp (what is known once opened), mcap/index_builder.hpp (opening:
// mcap/summary.hpp, mcap/data_walk.hpp, mcap/topics.hpp), mcap/chunks.hpp (records, chunks and
// message indexes read), mcap/cursor.hpp (reading).

#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/mcap/cursor.hpp"
#include "ulc/bags/mcap/file_index.hpp"
#include "ulc/bags/mcap/index_builder.hpp"
#include "ulc/bags/message_source.hpp"

namespace ulc::bags {

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
