// A closed ROS 1 bag's index (ros1_bag.hpp): the connection and chunk info records of its index
// section, then the index data records after each chunk, never a chunk's contents. Every count
// the bag header and the chunk infos announce is checked against what the file holds.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/ros1/bag_header.hpp"
#include "ulc/bags/ros1/contents.hpp"
#include "ulc/bags/ros1_records.hpp"
#include "ulc/io/endian.hpp"

namespace ulc::bags::ros1 {

/// Fills Contents from the index section of a bag whose header is `h`.
class IndexReader {
 public:
  IndexReader(const FileReader& file, Contents& contents) : file_(file), contents_(contents) {}

  void read(const BagHeader& h) {
    std::vector<ChunkInfo> infos;
    std::vector<unsigned char> header, data;
    for (std::uint64_t pos = h.index_pos; pos < file_.size();) {
      const auto r = read_record(file_, pos, header, "index");
      const FieldList f(header.data(), header.size(), file_place(file_), r.header_at);
      const std::uint8_t op = f.op();
      if (op == static_cast<std::uint8_t>(Op::connection)) {
        file_.read_at(r.data_at, r.data_size, data, "connection header");
        contents_.add_connection(f, data.data(), data.size(), file_place(file_), r.data_at);
      } else if (op == static_cast<std::uint8_t>(Op::chunk_info)) {
        infos.push_back(read_chunk_info(f, r, data));
      } else {
        file_.fail(pos, "a " + op_name(op) +
                            " record in the index section (only connection and chunk info "
                            "records belong there)");
      }
      pos = r.end();
    }
    check_count("connection", contents_.connections.size(), h.conn_count);
    check_count("chunk info", infos.size(), h.chunk_count);
    read_chunks(infos, h);
  }

 private:
  struct ChunkInfo {
    std::uint64_t record_pos = 0;
    std::uint64_t chunk_pos = 0;
    std::uint64_t messages = 0;  ///< the sum of its per-connection counts
  };

  void check_count(const char* what, std::size_t found, std::uint32_t announced) const {
    if (found != announced)
      file_.fail(kMagicSize, "the bag header announces " + std::to_string(announced) + " " + what +
                                 " records, the index holds " + std::to_string(found));
  }

  ChunkInfo read_chunk_info(const FieldList& f, const RecordSpan& r,
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
      Chunk c = chunk_at(file_, info.chunk_pos, buffer);
      c.index_begin = c.data_at + c.data_size;
      c.index_end = i + 1 < infos.size() ? infos[i + 1].chunk_pos : h.index_pos;
      if (c.index_end < c.index_begin)
        file_.fail(c.pos, "the chunk runs past byte " + std::to_string(c.index_end) +
                              ", where the next chunk or the index starts");
      contents_.add_chunk(file_, c);
      const std::uint64_t indexed = count_index_entries(contents_.chunks.back(), buffer);
      if (indexed != info.messages)
        file_.fail(info.record_pos, "chunk info counts " + std::to_string(info.messages) +
                                        " messages, the index data records after the chunk at "
                                        "byte " +
                                        std::to_string(c.pos) + " list " + std::to_string(indexed));
    }
  }

  std::uint64_t count_index_entries(const Chunk& c, std::vector<unsigned char>& buffer) {
    std::uint64_t n = 0;
    contents_.for_each_index_entry(file_, c, buffer,
                                   [&](std::size_t conn, std::int64_t t, std::uint32_t) {
                                     contents_.connections[conn].messages.add(t);
                                     ++n;
                                   });
    return n;
  }

  const FileReader& file_;
  Contents& contents_;
};

}  // namespace ulc::bags::ros1
