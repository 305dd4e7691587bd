// What opening a ROS 1 bag finds (ros1_bag.hpp): its connections, its chunks in file order and,
// after a linear scan, every message; and how a chunk record is read, decompressed and followed
// by its index data records.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/message_span.hpp"
#include "ulc/bags/ros1_records.hpp"
#include "ulc/io/endian.hpp"

namespace ulc::bags::ros1 {

/// A connection record: one publisher's topic and message type.
struct Connection {
  std::uint32_t id = 0;
  std::string topic;
  std::string type;
  std::string md5sum;
  std::size_t topic_index = 0;  ///< into Ros1Bag::topics()
  MessageSpan messages;
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

/// Where errors in the file's own records point.
inline Place file_place(const FileReader& file) {
  return Place{&file.name(), 0, Codec::none};
}

/// Where errors inside a chunk point: its data for an uncompressed chunk, else the chunk record.
inline Place chunk_place(const FileReader& file, const Chunk& c) {
  return Place{&file.name(), c.codec == Codec::none ? c.data_at : c.pos, c.codec};
}

/// The chunk of a chunk record whose header fields are `f`.
inline Chunk make_chunk(const RecordSpan& r, const FieldList& f) {
  Chunk c;
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
    f.fail("unknown chunk compression '" + printable(compression) +
           "' (expected none, bz2 or lz4)");
  }
  if (c.codec == Codec::none && c.size != c.data_size)
    f.fail("uncompressed chunk holds " + std::to_string(c.data_size) +
           " bytes, its header claims " + std::to_string(c.size));
  return c;
}

/// The chunk record at `pos` (its header read into `header`).
inline Chunk chunk_at(const FileReader& file, std::uint64_t pos,
                      std::vector<unsigned char>& header) {
  const auto r = read_record(file, pos, header, "chunk");
  const FieldList f(header.data(), header.size(), file_place(file), r.header_at);
  if (f.op() != static_cast<std::uint8_t>(Op::chunk))
    file.fail(pos, "expected a chunk record, found a " + op_name(f.op()) + " record");
  return make_chunk(r, f);
}

/// Reads chunk `c` into `out`, decompressed (`packed` holds the compressed bytes).
inline void load_chunk(const FileReader& file, const Chunk& c, std::vector<unsigned char>& out,
                       std::vector<unsigned char>& packed) {
  if (c.codec == Codec::none) return file.read_at(c.data_at, c.data_size, out, "chunk");
  file.read_at(c.data_at, c.data_size, packed, "chunk");
  decompress(c.codec, packed.data(), packed.size(), c.size, out, BlockPlace{file.name(), c.pos});
}

/// The connections and chunks of a bag, as its index or a linear scan lists them.
struct Contents {
  bool indexed = true;  ///< false after a linear scan
  std::vector<Connection> connections;
  std::unordered_map<std::uint32_t, std::size_t> connection_by_id;
  std::vector<Chunk> chunks;        ///< in file order
  std::vector<IndexEntry> scanned;  ///< every message, after a linear scan only

  /// Registers a connection record: its header's `conn` and `topic`, its data's connection
  /// header (`type`, `md5sum`). A connection defined again (in a chunk and in the index) must
  /// keep its topic.
  void add_connection(const FieldList& header, const unsigned char* data, std::size_t size,
                      const Place& place, std::uint64_t data_at) {
    const std::uint32_t id = header.u32("conn");
    const std::string_view topic = header.text("topic");
    const FieldList fields(data, size, place, data_at);
    const auto [it, added] = connection_by_id.emplace(id, connections.size());
    if (!added) {
      if (connections[it->second].topic != topic)
        header.fail("connection " + std::to_string(id) + " is defined again with topic '" +
                    printable(topic) + "', first with '" +
                    printable(connections[it->second].topic) + "'");
      return;
    }
    Connection c;
    c.id = id;
    c.topic = std::string(topic);
    c.type = std::string(fields.text("type"));
    c.md5sum = std::string(fields.find("md5sum").value_or(""));
    connections.push_back(std::move(c));
  }

  std::size_t connection_index(std::uint32_t id, const Place& place, std::uint64_t at) const {
    const auto it = connection_by_id.find(id);
    if (it == connection_by_id.end())
      place.fail(at, "connection " + std::to_string(id) + " has no connection record");
    return it->second;
  }

  void add_chunk(const FileReader& file, const Chunk& c) {
    if (chunks.size() >= 0xffffffffu) file.fail(c.pos, "more than 2^32 chunks");
    chunks.push_back(c);
  }

  /// Calls visit(connection, time, offset) for each entry of the index data records that
  /// follow chunk `c`, read into `buffer`.
  template <typename Visit>
  void for_each_index_entry(const FileReader& file, const Chunk& c,
                            std::vector<unsigned char>& buffer, Visit&& visit) const {
    file.read_at(c.index_begin, c.index_end - c.index_begin, buffer, "index data records");
    const Place place{&file.name(), c.index_begin, Codec::none};
    const unsigned char* p = buffer.data();
    for (std::uint64_t at = 0; at < buffer.size();) {
      const auto r = record_in_buffer(p, buffer.size(), at, place, "index data records");
      const FieldList f(p + r.header_at, r.header_size, place, r.header_at);
      if (f.op() != static_cast<std::uint8_t>(Op::index_data))
        place.fail(at, "a " + op_name(f.op()) + " record after the chunk at byte " +
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
        visit(conn, load_time(p + e), offset);
      }
      at = r.end();
    }
  }
};

}  // namespace ulc::bags::ros1
