// A ROS 1 bag without an index (ros1_bag.hpp): its records read one after the other and every
// chunk decompressed once to list its messages and connections. A record cut by the end of the
// file, or a chunk still holding an unfinished recording's zero sizes, ends the scan with a
// warning: the recorder stopped while writing it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/ros1/contents.hpp"
#include "ulc/bags/ros1_records.hpp"

namespace ulc::bags::ros1 {

/// Fills Contents (with `scanned`, every message) by walking the records from `pos`.
class LinearScan {
 public:
  LinearScan(const FileReader& file, Contents& contents, std::vector<std::string>& warnings)
      : file_(file), contents_(contents), warnings_(warnings) {}

  void scan(std::uint64_t pos) {
    contents_.indexed = false;
    std::vector<unsigned char> header, data, packed;
    while (pos < file_.size()) {
      const auto r = try_read_record(file_, pos, header);
      if (!r) return warn_cut(pos);
      const FieldList f(header.data(), header.size(), file_place(file_), r->header_at);
      const auto op = static_cast<Op>(f.op());
      if (op == Op::chunk) {
        const Chunk c = make_chunk(*r, f);
        if (c.size == 0 && c.data_size == 0) return warn_unfinished_chunk(pos);
        contents_.add_chunk(file_, c);
        load_chunk(file_, c, data, packed);
        scan_chunk(static_cast<std::uint32_t>(contents_.chunks.size() - 1), data);
      } else if (op == Op::connection) {
        file_.read_at(r->data_at, r->data_size, data, "connection header");
        contents_.add_connection(f, data.data(), data.size(), file_place(file_), r->data_at);
      } else if (op != Op::index_data && op != Op::chunk_info) {
        file_.fail(pos, "a " + op_name(f.op()) +
                            " record between chunks (expected chunk, index data, connection or "
                            "chunk info)");
      }
      pos = r->end();
    }
  }

 private:
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
    const Place place = chunk_place(file_, contents_.chunks[chunk]);
    const unsigned char* p = data.data();
    for (std::uint64_t at = 0; at < data.size();) {
      const auto r = record_in_buffer(p, data.size(), at, place, "chunk");
      const FieldList f(p + r.header_at, r.header_size, place, r.header_at);
      const auto op = static_cast<Op>(f.op());
      if (op == Op::message_data) {
        const std::size_t conn = contents_.connection_index(f.u32("conn"), place, at);
        const std::int64_t t = f.time("time");
        contents_.connections[conn].messages.add(t);
        contents_.scanned.push_back(
            {t, chunk, static_cast<std::uint32_t>(at), static_cast<std::uint32_t>(conn)});
      } else if (op == Op::connection) {
        contents_.add_connection(f, p + r.data_at, r.data_size, place, r.data_at);
      } else {
        place.fail(at, "a " + op_name(f.op()) +
                           " record inside a chunk (expected connection or message data)");
      }
      at = r.end();
    }
  }

  const FileReader& file_;
  Contents& contents_;
  std::vector<std::string>& warnings_;
};

}  // namespace ulc::bags::ros1
