// Ros1BagWriter: writes ROS 1 bags, format 2.0, laid out as rosbag writes them: the bag header
// record padded to 4096 bytes, chunks (each followed by one index data record per connection it
// holds), then at index_pos the connection records and one chunk info record per chunk; the bag
// header is rewritten with index_pos and the counts on close.
//
// Messages stream to disk: memory holds the chunk being filled and the small per-message index
// of that chunk. A connection record goes into the chunk of its connection's first message (as
// rosbag does) and into the index section.
//
// Every failure is an io::IoError naming the file.
#pragma once

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/ros1_records.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

/// A publisher's topic, as its connection header states it.
struct Ros1Connection {
  std::string topic;
  std::string type;  ///< "sensor_msgs/PointCloud2"
  std::string md5sum;
  std::string message_definition;
  std::string callerid;
  bool latching = false;
};

struct Ros1WriteOptions {
  Codec compression = Codec::none;  ///< none, bz2 or lz4
  std::size_t chunk_bytes = 768 * 1024;
  /// false leaves index_pos 0 and writes no index section: the file of an unfinished recording.
  bool write_index = true;
};

class Ros1BagWriter {
 public:
  explicit Ros1BagWriter(const std::filesystem::path& file, Ros1WriteOptions options = {})
      : name_(file.string()), options_(options) {
    if (options_.compression == Codec::zstd) fail("ROS 1 bags compress with bz2 or lz4, not zstd");
    file_ = std::fopen(name_.c_str(), "wb");
    if (file_ == nullptr)
      throw io::IoError(name_, "", std::string("cannot open for writing: ") + std::strerror(errno));
    put(ros1::kMagic, ros1::kMagicSize);
    write_bag_header(0, 0, 0);
  }
  Ros1BagWriter(const Ros1BagWriter&) = delete;
  Ros1BagWriter& operator=(const Ros1BagWriter&) = delete;

  /// Closes the file; an error here is swallowed (call close() to see it).
  ~Ros1BagWriter() {
    try {
      close();
    } catch (...) {
    }
  }

  /// A new connection; returns its id for write().
  std::uint32_t add_connection(const Ros1Connection& c) {
    check_open();
    connections_.push_back(c);
    defined_.push_back(false);
    chunk_index_.emplace_back();
    return static_cast<std::uint32_t>(connections_.size() - 1);
  }

  /// Appends one message received at `time_ns` (nanoseconds since the epoch, any order).
  void write(std::uint32_t connection, std::int64_t time_ns, const unsigned char* data,
             std::size_t size) {
    check_open();
    if (connection >= connections_.size())
      fail("write to connection " + std::to_string(connection) + ", only " +
           std::to_string(connections_.size()) + " were added");
    if (!ros1::representable_time(time_ns))
      fail("time " + std::to_string(time_ns) + " ns is outside the range of ROS time");
    if (size > kMaxRecordBytes - kRecordSlack)
      fail("message of " + std::to_string(size) + " bytes: more than a chunk may hold");
    if (!chunk_.empty() && chunk_.size() + size + kRecordSlack > kMaxRecordBytes) flush_chunk();
    if (!defined_[connection]) append_connection(chunk_, connection);
    defined_[connection] = true;
    append_message(connection, time_ns, data, size);
    if (chunk_.size() >= options_.chunk_bytes) flush_chunk();
  }

  /// Writes the last chunk and the index, rewrites the bag header and closes the file.
  void close() {
    if (file_ == nullptr) return;
    try {
      flush_chunk();
      if (options_.write_index) write_index();
    } catch (...) {
      std::fclose(file_);
      file_ = nullptr;
      throw;
    }
    const bool ok = std::fclose(file_) == 0;
    file_ = nullptr;
    if (!ok) fail(std::string("cannot finish writing: ") + std::strerror(errno));
  }

 private:
  /// Room for a message record's header (and a connection record) beside its data.
  static constexpr std::uint64_t kRecordSlack = 1 << 20;

  struct IndexItem {
    std::int64_t time_ns;
    std::uint32_t offset;
  };
  struct ChunkInfo {
    std::uint64_t pos;
    std::int64_t start_ns;
    std::int64_t end_ns;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> counts;  ///< (connection, messages)
  };

  [[noreturn]] void fail(const std::string& reason) const { throw io::IoError(name_, "", reason); }

  void check_open() const {
    if (file_ == nullptr) fail("the bag writer is closed");
  }

  void put(const void* p, std::size_t n) {
    if (n != 0 && std::fwrite(p, 1, n, file_) != n)
      fail(std::string("write failed: ") + std::strerror(errno));
    pos_ += n;
  }
  void put_u32(std::uint32_t v) {
    unsigned char b[4];
    io::store_le(b, v);
    put(b, 4);
  }
  /// A whole record: header fields, then data.
  void put_record(const ros1::FieldWriter& header, const unsigned char* data, std::size_t n) {
    put_u32(static_cast<std::uint32_t>(header.data().size()));
    put(header.data().data(), header.data().size());
    put_u32(static_cast<std::uint32_t>(n));
    put(data, n);
  }

  static void append_u32(std::vector<unsigned char>& out, std::uint32_t v) {
    unsigned char b[4];
    io::store_le(b, v);
    out.insert(out.end(), b, b + 4);
  }
  static void append_record(std::vector<unsigned char>& out, const ros1::FieldWriter& header,
                            const unsigned char* data, std::size_t n) {
    append_u32(out, static_cast<std::uint32_t>(header.data().size()));
    out.insert(out.end(), header.data().begin(), header.data().end());
    append_u32(out, static_cast<std::uint32_t>(n));
    out.insert(out.end(), data, data + n);
  }

  /// The bag header record (op 0x03), padded with spaces to 4096 bytes.
  void write_bag_header(std::uint64_t index_pos, std::uint32_t conn_count,
                        std::uint32_t chunk_count) {
    ros1::FieldWriter h;
    h.op(ros1::Op::bag_header)
        .u64("index_pos", index_pos)
        .u32("conn_count", conn_count)
        .u32("chunk_count", chunk_count);
    const std::vector<unsigned char> padding(ros1::kBagHeaderPadded - h.data().size(), ' ');
    put_record(h, padding.data(), padding.size());
  }

  /// A connection record (op 0x07): header conn and topic; data the connection header.
  void append_connection(std::vector<unsigned char>& out, std::uint32_t id) const {
    const Ros1Connection& c = connections_[id];
    ros1::FieldWriter header;
    header.op(ros1::Op::connection).u32("conn", id).text("topic", c.topic);
    ros1::FieldWriter fields;
    fields.text("topic", c.topic).text("type", c.type).text("md5sum", c.md5sum);
    fields.text("message_definition", c.message_definition);
    if (!c.callerid.empty()) fields.text("callerid", c.callerid);
    if (c.latching) fields.text("latching", "1");
    append_record(out, header, fields.data().data(), fields.data().size());
  }

  /// A message data record (op 0x02) into the chunk, and its index entry.
  void append_message(std::uint32_t connection, std::int64_t time_ns, const unsigned char* data,
                      std::size_t size) {
    if (index_items_ == 0) chunk_start_ = chunk_end_ = time_ns;
    chunk_start_ = std::min(chunk_start_, time_ns);
    chunk_end_ = std::max(chunk_end_, time_ns);
    chunk_index_[connection].push_back({time_ns, static_cast<std::uint32_t>(chunk_.size())});
    ++index_items_;
    ros1::FieldWriter header;
    header.op(ros1::Op::message_data).u32("conn", connection).time("time", time_ns);
    append_record(chunk_, header, data, size);
  }

  /// Writes the chunk record (op 0x05) and the index data records (op 0x04) after it.
  void flush_chunk() {
    if (chunk_.empty()) return;
    ChunkInfo info{pos_, chunk_start_, chunk_end_, {}};
    ros1::FieldWriter header;
    header.op(ros1::Op::chunk)
        .text("compression", codec_name(options_.compression))
        .u32("size", static_cast<std::uint32_t>(chunk_.size()));
    if (options_.compression == Codec::none) {
      put_record(header, chunk_.data(), chunk_.size());
    } else {
      const auto packed = compress(options_.compression, chunk_.data(), chunk_.size());
      put_record(header, packed.data(), packed.size());
    }
    for (std::uint32_t id = 0; id < chunk_index_.size(); ++id) {
      if (chunk_index_[id].empty()) continue;
      write_index_data(id, chunk_index_[id]);
      info.counts.emplace_back(id, static_cast<std::uint32_t>(chunk_index_[id].size()));
      chunk_index_[id].clear();
    }
    chunk_infos_.push_back(std::move(info));
    chunk_.clear();
    index_items_ = 0;
  }

  void write_index_data(std::uint32_t id, const std::vector<IndexItem>& items) {
    ros1::FieldWriter header;
    header.op(ros1::Op::index_data)
        .u32("ver", 1)
        .u32("conn", id)
        .u32("count", static_cast<std::uint32_t>(items.size()));
    std::vector<unsigned char> data(items.size() * 12);
    for (std::size_t k = 0; k < items.size(); ++k) {
      ros1::store_time(data.data() + 12 * k, items[k].time_ns);
      io::store_le(data.data() + 12 * k + 8, items[k].offset);
    }
    put_record(header, data.data(), data.size());
  }

  /// The index section: connection records, chunk info records (op 0x06); then the bag header
  /// is rewritten to point at it.
  void write_index() {
    const std::uint64_t index_pos = pos_;
    std::vector<unsigned char> record;
    for (std::uint32_t id = 0; id < connections_.size(); ++id) {
      record.clear();
      append_connection(record, id);
      put(record.data(), record.size());
    }
    for (const ChunkInfo& info : chunk_infos_) write_chunk_info(info);
    if (std::fseek(file_, static_cast<long>(ros1::kMagicSize), SEEK_SET) != 0)
      fail(std::string("cannot seek to the bag header: ") + std::strerror(errno));
    write_bag_header(index_pos, static_cast<std::uint32_t>(connections_.size()),
                     static_cast<std::uint32_t>(chunk_infos_.size()));
  }

  void write_chunk_info(const ChunkInfo& info) {
    ros1::FieldWriter header;
    header.op(ros1::Op::chunk_info)
        .u32("ver", 1)
        .u64("chunk_pos", info.pos)
        .time("start_time", info.start_ns)
        .time("end_time", info.end_ns)
        .u32("count", static_cast<std::uint32_t>(info.counts.size()));
    std::vector<unsigned char> data;
    for (const auto& [id, n] : info.counts) {
      append_u32(data, id);
      append_u32(data, n);
    }
    put_record(header, data.data(), data.size());
  }

  std::string name_;
  Ros1WriteOptions options_;
  std::FILE* file_ = nullptr;
  std::uint64_t pos_ = 0;  ///< bytes written so far: the next record's offset
  std::vector<Ros1Connection> connections_;
  std::vector<bool> defined_;  ///< per connection: its record is in a chunk already
  std::vector<unsigned char> chunk_;
  std::vector<std::vector<IndexItem>> chunk_index_;  ///< per connection, the current chunk's
  std::size_t index_items_ = 0;
  std::int64_t chunk_start_ = 0;
  std::int64_t chunk_end_ = 0;
  std::vector<ChunkInfo> chunk_infos_;
};

}  // namespace ulc::bags
