// Ros1Bag: reads ROS 1 bags, format 2.0 (http://wiki.ros.org/Bags/Format/2.0).
//
// A bag is a bag header record, then chunks (each followed by one index data record per
// connection it holds: the time and offset of each message inside the chunk), then, at the
// bag header's index_pos, the connection records and one chunk info record per chunk.
//
// Opening reads the bag header, the index section and the index data records after each chunk:
// never a chunk's contents. A cursor collects the index entries of the topics asked for, sorts
// them by time and walks them, decompressing each chunk when first needed and dropping it after
// its last message, so chunks out of time order still give messages in time order and each
// chunk is decompressed once.
//
// A bag without an index (index_pos 0: an unfinished recording) is read by a linear scan of its
// records, which builds the same index; a record cut by the end of such a file (the recorder
// stopped while writing it) ends the scan with a warning. A bag whose header names an index that
// the file does not reach was cut after it was closed: that is an error, like every other problem,
// an io::IoError
// naming the file, the byte and the problem.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/bags/ros1_records.hpp"

namespace ulc::bags {

namespace ros1 {

/// A connection record: one publisher's topic and message type.
struct Connection {
  std::uint32_t id = 0;
  std::string topic;
  std::string type;
  std::string md5sum;
  std::size_t topic_index = 0;  ///< into Ros1Bag::topics()
  std::uint64_t count = 0;
  std::int64_t first_ns = 0;
  std::int64_t last_ns = 0;

  void count_message(std::int64_t t) {
    first_ns = count == 0 ? t : std::min(first_ns, t);
    last_ns = count == 0 ? t : std::max(last_ns, t);
    ++count;
  }
};

/// A chunk record: where its (compressed) data and the index data records after it lie.
struct Chunk {
  std::uint64_t pos = 0;  ///< the chunk record
  std::uint64_t data_at = 0;
  std::uint64_t data_size = 0;
  std::uint64_t size = 0;  ///< uncompressed
  Codec codec = Codec::none;
  std::uint64_t index_begin = 0;  ///< the index data records that follow the chunk
  std::uint64_t index_end = 0;
};

/// One message: when it was received and where its message data record lies.
struct IndexEntry {
  std::int64_t time_ns;
  std::uint32_t chunk;       ///< into the bag's chunks, which are in file order
  std::uint32_t offset;      ///< in the decompressed chunk
  std::uint32_t connection;  ///< into the bag's connections
};

/// Printable text of a header value that may hold any bytes, for error messages.
inline std::string printable(std::string_view s) {
  std::string out;
  for (const char c : s.substr(0, 40)) out += c >= 32 && c < 127 ? c : '?';
  return s.size() > 40 ? out + "..." : out;
}

}  // namespace ros1

class Ros1Cursor;

class Ros1Bag : public MessageSource {
 public:
  explicit Ros1Bag(const std::filesystem::path& file) : file_(file) {
    check_magic();
    const BagHeader h = read_bag_header();
    if (h.index_pos == 0) {
      warnings_.push_back(
          "no index (the bag header's index_pos is 0: an unfinished recording): read by a "
          "linear scan");
      scan(h.end);
    } else if (index_cut(h)) {
      // A closed recording that lost its end: a damaged file, not an unfinished one.
      file_.fail(file_.size(), "truncated bag: the bag header puts the index at byte " +
                                   std::to_string(h.index_pos) + ", the file ends at byte " +
                                   std::to_string(file_.size()));
    } else {
      read_index(h);
    }
    build_topics();
  }

  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::vector<std::string> warnings() const override { return warnings_; }
  std::unique_ptr<MessageCursor> cursor(const std::vector<std::size_t>& selected,
                                        TimeWindow window) const override;

  /// True when the bag's index was read; false after a linear scan.
  bool indexed() const { return indexed_; }
  const std::string& file() const { return file_.name(); }

 private:
  friend class Ros1Cursor;

  struct BagHeader {
    std::uint64_t index_pos = 0;
    std::uint32_t conn_count = 0;
    std::uint32_t chunk_count = 0;
    std::uint64_t end = 0;  ///< of the bag header record: where the chunks start
  };
  struct ChunkInfo {
    std::uint64_t record_pos = 0;
    std::uint64_t chunk_pos = 0;
    std::uint64_t messages = 0;  ///< the sum of its per-connection counts
  };

  ros1::Place file_place() const { return ros1::Place{&file_.name(), 0, Codec::none}; }
  ros1::Place chunk_place(const ros1::Chunk& c) const {
    return ros1::Place{&file_.name(), c.codec == Codec::none ? c.data_at : c.pos, c.codec};
  }

  // --- the bag header ---

  void check_magic() const {
    if (file_.size() == 0) file_.fail(0, "empty file, not a ROS bag");
    const std::uint64_t n = std::min<std::uint64_t>(file_.size(), ros1::kMagicSize);
    std::vector<unsigned char> head;
    file_.read_at(0, n, head, "magic");
    const std::string_view text(reinterpret_cast<const char*>(head.data()), head.size());
    const std::string_view magic(ros1::kMagic, ros1::kMagicSize);
    if (text == magic) return;
    if (magic.substr(0, n) == text) file_.fail(0, "truncated: the file ends inside the magic");
    if (text.substr(0, 9) == magic.substr(0, 9))
      file_.fail(0, "ROS bag format version '" + ros1::printable(text.substr(9, n - 10)) +
                        "' is not supported (only 2.0)");
    file_.fail(0, "not a ROS bag: the file does not start with \"#ROSBAG V2.0\"");
  }

  BagHeader read_bag_header() const {
    std::vector<unsigned char> header;
    const auto r = ros1::read_record(file_, ros1::kMagicSize, header, "bag header");
    const ros1::FieldList f(header.data(), header.size(), file_place(), r.header_at);
    if (f.op() != static_cast<std::uint8_t>(ros1::Op::bag_header))
      file_.fail(r.pos,
                 "expected the bag header record, found a " + ros1::op_name(f.op()) + " record");
    BagHeader h{f.u64("index_pos"), f.u32("conn_count"), f.u32("chunk_count"), r.end()};
    if (h.index_pos != 0 && h.index_pos < h.end)
      f.fail("index_pos " + std::to_string(h.index_pos) + " points inside the bag header");
    return h;
  }

  /// A file cut before its index: index_pos past the end, or at the end with records announced.
  bool index_cut(const BagHeader& h) const {
    if (h.index_pos > file_.size()) return true;
    return h.index_pos == file_.size() && (h.conn_count != 0 || h.chunk_count != 0);
  }

  // --- the index: connection and chunk info records, index data records after each chunk ---

  void read_index(const BagHeader& h) {
    std::vector<ChunkInfo> infos;
    std::vector<unsigned char> header, data;
    for (std::uint64_t pos = h.index_pos; pos < file_.size();) {
      const auto r = ros1::read_record(file_, pos, header, "index");
      const ros1::FieldList f(header.data(), header.size(), file_place(), r.header_at);
      const std::uint8_t op = f.op();
      if (op == static_cast<std::uint8_t>(ros1::Op::connection)) {
        file_.read_at(r.data_at, r.data_size, data, "connection header");
        add_connection(f, data.data(), data.size(), file_place(), r.data_at);
      } else if (op == static_cast<std::uint8_t>(ros1::Op::chunk_info)) {
        infos.push_back(read_chunk_info(f, r, data));
      } else {
        file_.fail(pos, "a " + ros1::op_name(op) +
                            " record in the index section (only connection and chunk info "
                            "records belong there)");
      }
      pos = r.end();
    }
    check_count("connection", connections_.size(), h.conn_count);
    check_count("chunk info", infos.size(), h.chunk_count);
    read_chunks(infos, h);
  }

  void check_count(const char* what, std::size_t found, std::uint32_t announced) const {
    if (found != announced)
      file_.fail(ros1::kMagicSize, "the bag header announces " + std::to_string(announced) + " " +
                                       what + " records, the index holds " + std::to_string(found));
  }

  ChunkInfo read_chunk_info(const ros1::FieldList& f, const ros1::RecordSpan& r,
                            std::vector<unsigned char>& data) const {
    if (f.u32("ver") != 1)
      f.fail("chunk info record version " + std::to_string(f.u32("ver")) +
             " is not supported (only 1)");
    const std::uint32_t connections = f.u32("count");
    if (r.data_size != std::uint64_t{connections} * 8)
      f.fail("chunk info record lists " + std::to_string(connections) + " connections in " +
             std::to_string(r.data_size) + " bytes, expected 8 bytes each");
    file_.read_at(r.data_at, r.data_size, data, "chunk info");
    ChunkInfo info{r.pos, f.u64("chunk_pos"), 0};
    for (std::uint32_t k = 0; k < connections; ++k)
      info.messages += io::load_le<std::uint32_t>(data.data() + 8 * k + 4);
    return info;
  }

  /// The chunks in file order, each with the index data records that follow it (up to the next
  /// chunk or the index section); counts the messages of each connection.
  void read_chunks(std::vector<ChunkInfo>& infos, const BagHeader& h) {
    std::sort(infos.begin(), infos.end(),
              [](const ChunkInfo& a, const ChunkInfo& b) { return a.chunk_pos < b.chunk_pos; });
    std::vector<unsigned char> buffer;
    for (std::size_t i = 0; i < infos.size(); ++i) {
      const ChunkInfo& info = infos[i];
      if (info.chunk_pos < h.end || info.chunk_pos >= h.index_pos)
        file_.fail(info.record_pos, "chunk info points to byte " + std::to_string(info.chunk_pos) +
                                        ", outside the chunks (bytes " + std::to_string(h.end) +
                                        " to " + std::to_string(h.index_pos) + ")");
      ros1::Chunk c = chunk_at(info.chunk_pos, buffer);
      c.index_begin = c.data_at + c.data_size;
      c.index_end = i + 1 < infos.size() ? infos[i + 1].chunk_pos : h.index_pos;
      if (c.index_end < c.index_begin)
        file_.fail(c.pos, "the chunk runs past byte " + std::to_string(c.index_end) +
                              ", where the next chunk or the index starts");
      add_chunk(c);
      const std::uint64_t indexed = count_index_entries(chunks_.back(), buffer);
      if (indexed != info.messages)
        file_.fail(info.record_pos, "chunk info counts " + std::to_string(info.messages) +
                                        " messages, the index data records after the chunk at "
                                        "byte " +
                                        std::to_string(c.pos) + " list " + std::to_string(indexed));
    }
  }

  std::uint64_t count_index_entries(const ros1::Chunk& c, std::vector<unsigned char>& buffer) {
    std::uint64_t n = 0;
    for_each_index_entry(c, buffer, [&](std::size_t conn, std::int64_t t, std::uint32_t) {
      connections_[conn].count_message(t);
      ++n;
    });
    return n;
  }

  /// Calls visit(connection, time, offset) for each entry of the index data records that
  /// follow chunk `c`, read into `buffer`.
  template <typename Visit>
  void for_each_index_entry(const ros1::Chunk& c, std::vector<unsigned char>& buffer,
                            Visit&& visit) const {
    file_.read_at(c.index_begin, c.index_end - c.index_begin, buffer, "index data records");
    const ros1::Place place{&file_.name(), c.index_begin, Codec::none};
    const unsigned char* p = buffer.data();
    for (std::uint64_t at = 0; at < buffer.size();) {
      const auto r = ros1::record_in_buffer(p, buffer.size(), at, place, "index data records");
      const ros1::FieldList f(p + r.header_at, r.header_size, place, r.header_at);
      if (f.op() != static_cast<std::uint8_t>(ros1::Op::index_data))
        place.fail(at, "a " + ros1::op_name(f.op()) + " record after the chunk at byte " +
                           std::to_string(c.pos) + ", where its index data records belong");
      if (f.u32("ver") != 1)
        f.fail("index data record version " + std::to_string(f.u32("ver")) +
               " is not supported (only 1)");
      const std::size_t conn = connection_index(f.u32("conn"), place, at);
      const std::uint32_t count = f.u32("count");
      if (r.data_size != std::uint64_t{count} * 12)
        f.fail("index data record lists " + std::to_string(count) + " messages in " +
               std::to_string(r.data_size) + " bytes, expected 12 bytes each");
      for (std::uint64_t e = r.data_at; e < r.end(); e += 12) {
        const std::uint32_t offset = io::load_le<std::uint32_t>(p + e + 8);
        if (offset >= c.size)
          place.fail(e, "index entry points to byte " + std::to_string(offset) +
                            " of the chunk at byte " + std::to_string(c.pos) + ", which holds " +
                            std::to_string(c.size) + " bytes");
        visit(conn, ros1::load_time(p + e), offset);
      }
      at = r.end();
    }
  }

  // --- the linear scan ---

  void scan(std::uint64_t pos) {
    indexed_ = false;
    std::vector<unsigned char> header, data, packed;
    while (pos < file_.size()) {
      const auto r = ros1::try_read_record(file_, pos, header);
      if (!r) return warn_cut(pos);
      const ros1::FieldList f(header.data(), header.size(), file_place(), r->header_at);
      const auto op = static_cast<ros1::Op>(f.op());
      if (op == ros1::Op::chunk) {
        const ros1::Chunk c = make_chunk(*r, f);
        if (c.size == 0 && c.data_size == 0) return warn_unfinished_chunk(pos);
        add_chunk(c);
        load_chunk(static_cast<std::uint32_t>(chunks_.size() - 1), data, packed);
        scan_chunk(static_cast<std::uint32_t>(chunks_.size() - 1), data);
      } else if (op == ros1::Op::connection) {
        file_.read_at(r->data_at, r->data_size, data, "connection header");
        add_connection(f, data.data(), data.size(), file_place(), r->data_at);
      } else if (op != ros1::Op::index_data && op != ros1::Op::chunk_info) {
        file_.fail(pos, "a " + ros1::op_name(f.op()) +
                            " record between chunks (expected chunk, index data, connection or "
                            "chunk info)");
      }
      pos = r->end();
    }
  }

  void warn_cut(std::uint64_t pos) {
    warnings_.push_back("the file ends inside the record at byte " + std::to_string(pos) +
                        " (a cut recording): its last " + std::to_string(file_.size() - pos) +
                        " bytes are ignored");
  }

  /// rosbag writes a chunk's header with sizes 0 and fills them in when the chunk is complete.
  void warn_unfinished_chunk(std::uint64_t pos) {
    warnings_.push_back("the chunk at byte " + std::to_string(pos) +
                        " still has the zero sizes of an unfinished recording: the last " +
                        std::to_string(file_.size() - pos) + " bytes are ignored");
  }

  /// Records the messages of a decompressed chunk and the connections it defines.
  void scan_chunk(std::uint32_t chunk, const std::vector<unsigned char>& data) {
    const ros1::Place place = chunk_place(chunks_[chunk]);
    const unsigned char* p = data.data();
    for (std::uint64_t at = 0; at < data.size();) {
      const auto r = ros1::record_in_buffer(p, data.size(), at, place, "chunk");
      const ros1::FieldList f(p + r.header_at, r.header_size, place, r.header_at);
      const auto op = static_cast<ros1::Op>(f.op());
      if (op == ros1::Op::message_data) {
        const std::size_t conn = connection_index(f.u32("conn"), place, at);
        const std::int64_t t = f.time("time");
        connections_[conn].count_message(t);
        scanned_.push_back(
            {t, chunk, static_cast<std::uint32_t>(at), static_cast<std::uint32_t>(conn)});
      } else if (op == ros1::Op::connection) {
        add_connection(f, p + r.data_at, r.data_size, place, r.data_at);
      } else {
        place.fail(at, "a " + ros1::op_name(f.op()) +
                           " record inside a chunk (expected connection or message data)");
      }
      at = r.end();
    }
  }

  // --- chunks and connections ---

  /// The chunk record at `pos` (its header read into `header`).
  ros1::Chunk chunk_at(std::uint64_t pos, std::vector<unsigned char>& header) const {
    const auto r = ros1::read_record(file_, pos, header, "chunk");
    const ros1::FieldList f(header.data(), header.size(), file_place(), r.header_at);
    if (f.op() != static_cast<std::uint8_t>(ros1::Op::chunk))
      file_.fail(pos, "expected a chunk record, found a " + ros1::op_name(f.op()) + " record");
    return make_chunk(r, f);
  }

  ros1::Chunk make_chunk(const ros1::RecordSpan& r, const ros1::FieldList& f) const {
    ros1::Chunk c;
    c.pos = r.pos;
    c.data_at = r.data_at;
    c.data_size = r.data_size;
    c.size = f.u32("size");
    const std::string_view compression = f.text("compression");
    if (compression == "none") {
      c.codec = Codec::none;
    } else if (compression == "bz2") {
      c.codec = Codec::bz2;
    } else if (compression == "lz4") {
      c.codec = Codec::lz4;
    } else {
      f.fail("unknown chunk compression '" + ros1::printable(compression) +
             "' (expected none, bz2 or lz4)");
    }
    if (c.codec == Codec::none && c.size != c.data_size)
      f.fail("uncompressed chunk holds " + std::to_string(c.data_size) +
             " bytes, its header claims " + std::to_string(c.size));
    return c;
  }

  void add_chunk(const ros1::Chunk& c) {
    if (chunks_.size() >= 0xffffffffu) file_.fail(c.pos, "more than 2^32 chunks");
    chunks_.push_back(c);
  }

  /// Reads chunk `chunk` into `out`, decompressed (`packed` holds the compressed bytes).
  void load_chunk(std::uint32_t chunk, std::vector<unsigned char>& out,
                  std::vector<unsigned char>& packed) const {
    const ros1::Chunk& c = chunks_[chunk];
    if (c.codec == Codec::none) return file_.read_at(c.data_at, c.data_size, out, "chunk");
    file_.read_at(c.data_at, c.data_size, packed, "chunk");
    decompress(c.codec, packed.data(), packed.size(), c.size, out, BlockPlace{file_.name(), c.pos});
  }

  /// Registers a connection record: its header's `conn` and `topic`, its data's connection
  /// header (`type`, `md5sum`). A connection defined again (in a chunk and in the index) must
  /// keep its topic.
  void add_connection(const ros1::FieldList& header, const unsigned char* data, std::size_t size,
                      const ros1::Place& place, std::uint64_t data_at) {
    const std::uint32_t id = header.u32("conn");
    const std::string_view topic = header.text("topic");
    const ros1::FieldList fields(data, size, place, data_at);
    const auto [it, added] = connection_by_id_.emplace(id, connections_.size());
    if (!added) {
      if (connections_[it->second].topic != topic)
        header.fail("connection " + std::to_string(id) + " is defined again with topic '" +
                    ros1::printable(topic) + "', first with '" +
                    ros1::printable(connections_[it->second].topic) + "'");
      return;
    }
    ros1::Connection c;
    c.id = id;
    c.topic = std::string(topic);
    c.type = std::string(fields.text("type"));
    c.md5sum = std::string(fields.find("md5sum").value_or(""));
    connections_.push_back(std::move(c));
  }

  std::size_t connection_index(std::uint32_t id, const ros1::Place& place, std::uint64_t at) const {
    const auto it = connection_by_id_.find(id);
    if (it == connection_by_id_.end())
      place.fail(at, "connection " + std::to_string(id) + " has no connection record");
    return it->second;
  }

  /// One TopicInfo per topic name, sorted by name, merging the connections that carry it.
  void build_topics() {
    std::vector<std::size_t> order(connections_.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return connections_[a].topic < connections_[b].topic;
    });
    for (const std::size_t k : order) {
      ros1::Connection& c = connections_[k];
      if (topics_.empty() || topics_.back().name != c.topic) {
        topics_.push_back(TopicInfo{c.topic, c.type, Serialization::ros1, 0, 0, 0, 0});
      } else if (topics_.back().type != c.type) {
        warnings_.push_back("topic " + c.topic + " has connections of types " +
                            topics_.back().type + " and " + c.type + ": listed as " +
                            topics_.back().type);
      }
      c.topic_index = topics_.size() - 1;
      add_counts(topics_.back(), c);
    }
  }

  static void add_counts(TopicInfo& t, const ros1::Connection& c) {
    ++t.connections;
    if (c.count == 0) return;
    t.first_time_ns = t.message_count == 0 ? c.first_ns : std::min(t.first_time_ns, c.first_ns);
    t.last_time_ns = t.message_count == 0 ? c.last_ns : std::max(t.last_time_ns, c.last_ns);
    t.message_count += c.count;
  }

  // --- what a cursor reads ---

  /// The index entries of the chosen connections inside `window`, in time order (ties in file
  /// order).
  std::vector<ros1::IndexEntry> select(const std::vector<bool>& wanted, TimeWindow window) const {
    std::vector<ros1::IndexEntry> entries;
    if (indexed_) {
      std::vector<unsigned char> buffer;
      for (std::size_t k = 0; k < chunks_.size(); ++k) {
        const auto chunk = static_cast<std::uint32_t>(k);
        for_each_index_entry(
            chunks_[k], buffer, [&](std::size_t conn, std::int64_t t, std::uint32_t offset) {
              if (wanted[conn] && window.contains(t))
                entries.push_back({t, chunk, offset, static_cast<std::uint32_t>(conn)});
            });
      }
    } else {
      for (const ros1::IndexEntry& e : scanned_)
        if (wanted[e.connection] && window.contains(e.time_ns)) entries.push_back(e);
    }
    std::sort(entries.begin(), entries.end(),
              [](const ros1::IndexEntry& a, const ros1::IndexEntry& b) {
                if (a.time_ns != b.time_ns) return a.time_ns < b.time_ns;
                if (a.chunk != b.chunk) return a.chunk < b.chunk;
                return a.offset < b.offset;
              });
    return entries;
  }

  FileReader file_;
  bool indexed_ = true;
  std::vector<ros1::Connection> connections_;
  std::unordered_map<std::uint32_t, std::size_t> connection_by_id_;
  std::vector<ros1::Chunk> chunks_;        ///< in file order
  std::vector<ros1::IndexEntry> scanned_;  ///< every message, after a linear scan only
  std::vector<TopicInfo> topics_;
  std::vector<std::string> warnings_;
};

/// Walks the sorted index entries of a selection, keeping the decompressed chunks that later
/// entries still need (at most kMaxOpenChunks; beyond that the one needed last is dropped and
/// decompressed again when its turn comes).
class Ros1Cursor : public MessageCursor {
 public:
  static constexpr std::size_t kMaxOpenChunks = 8;

  Ros1Cursor(const Ros1Bag& bag, std::vector<ros1::IndexEntry> entries)
      : bag_(bag), entries_(std::move(entries)), last_use_(bag.chunks_.size(), 0) {
    for (std::size_t k = 0; k < entries_.size(); ++k) last_use_[entries_[k].chunk] = k;
  }

  bool next(MessageView& out) override {
    if (next_ >= entries_.size()) return false;
    const ros1::IndexEntry& e = entries_[next_];
    const ros1::Chunk& c = bag_.chunks_[e.chunk];
    const std::vector<unsigned char>& data = chunk(e.chunk);
    const ros1::Place place = bag_.chunk_place(c);
    const auto r = ros1::record_in_buffer(data.data(), data.size(), e.offset, place, "chunk");
    const ros1::FieldList f(data.data() + r.header_at, r.header_size, place, r.header_at);
    if (f.op() != static_cast<std::uint8_t>(ros1::Op::message_data))
      place.fail(e.offset, "the index points to a " + ros1::op_name(f.op()) +
                               " record, expected message data");
    const ros1::Connection& conn = bag_.connections_[e.connection];
    if (f.u32("conn") != conn.id || f.time("time") != e.time_ns)
      place.fail(e.offset,
                 "the message data record does not match its index entry "
                 "(connection " +
                     std::to_string(conn.id) + ", time " + std::to_string(e.time_ns) + " ns)");
    out.topic = conn.topic_index;
    out.time_ns = e.time_ns;
    out.data = data.data() + r.data_at;
    out.size = static_cast<std::size_t>(r.data_size);
    out.file = &bag_.file_.name();
    out.offset = c.codec == Codec::none ? c.data_at + e.offset : c.pos;
    ++next_;
    return true;
  }

 private:
  struct Slot {
    std::uint32_t chunk;
    std::vector<unsigned char> data;
  };

  /// The decompressed chunk, from the open ones or loaded now.
  const std::vector<unsigned char>& chunk(std::uint32_t c) {
    for (const Slot& s : slots_)
      if (s.chunk == c) return s.data;
    release_finished();
    if (slots_.size() >= kMaxOpenChunks) drop(needed_last());
    Slot s{c, {}};
    if (!spare_.empty()) {
      s.data = std::move(spare_.back());
      spare_.pop_back();
    }
    bag_.load_chunk(c, s.data, packed_);
    slots_.push_back(std::move(s));
    return slots_.back().data;
  }

  /// Drops the chunks no later entry needs.
  void release_finished() {
    for (std::size_t k = 0; k < slots_.size();) {
      if (last_use_[slots_[k].chunk] < next_) {
        drop(k);
      } else {
        ++k;
      }
    }
  }

  std::size_t needed_last() const {
    std::size_t worst = 0;
    for (std::size_t k = 1; k < slots_.size(); ++k)
      if (last_use_[slots_[k].chunk] > last_use_[slots_[worst].chunk]) worst = k;
    return worst;
  }

  /// Keeps the slot's buffer for the next chunk (its capacity saves an allocation).
  void drop(std::size_t k) {
    spare_.push_back(std::move(slots_[k].data));
    slots_[k] = std::move(slots_.back());
    slots_.pop_back();
  }

  const Ros1Bag& bag_;
  std::vector<ros1::IndexEntry> entries_;
  std::vector<std::size_t> last_use_;  ///< per chunk: the last entry that reads it
  std::size_t next_ = 0;
  std::vector<Slot> slots_;
  std::vector<std::vector<unsigned char>> spare_;
  std::vector<unsigned char> packed_;
};

inline std::unique_ptr<MessageCursor> Ros1Bag::cursor(const std::vector<std::size_t>& selected,
                                                      TimeWindow window) const {
  std::vector<bool> topic_wanted(topics_.size(), false);
  for (const std::size_t t : selected) {
    if (t >= topics_.size())
      throw std::out_of_range("Ros1Bag::cursor: topic index " + std::to_string(t) + ", " +
                              file_.name() + " has " + std::to_string(topics_.size()) + " topics");
    topic_wanted[t] = true;
  }
  std::vector<bool> wanted(connections_.size());
  for (std::size_t k = 0; k < connections_.size(); ++k)
    wanted[k] = topic_wanted[connections_[k].topic_index];
  return std::make_unique<Ros1Cursor>(*this, select(wanted, window));
}

}  // namespace ulc::bags
