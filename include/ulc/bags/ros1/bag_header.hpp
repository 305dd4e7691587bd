// The start of a ROS 1 bag (ros1_bag.hpp): the magic "#ROSBAG V2.0" and the bag header record,
// which says where the index section is and how many connection and chunk info records it holds.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/ros1/contents.hpp"
#include "ulc/bags/ros1_records.hpp"

namespace ulc::bags::ros1 {

struct BagHeader {
  std::uint64_t index_pos = 0;
  std::uint32_t conn_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t end = 0;  ///< of the bag header record: where the chunks start
};

inline void check_magic(const FileReader& file) {
  if (file.size() == 0) file.fail(0, "empty file, not a ROS bag");
  const std::uint64_t n = std::min<std::uint64_t>(file.size(), kMagicSize);
  std::vector<unsigned char> head;
  file.read_at(0, n, head, "magic");
  const std::string_view text(reinterpret_cast<const char*>(head.data()), head.size());
  const std::string_view magic(kMagic, kMagicSize);
  if (text == magic) return;
  if (magic.substr(0, n) == text) file.fail(0, "truncated: the file ends inside the magic");
  if (text.substr(0, 9) == magic.substr(0, 9))
    file.fail(0, "ROS bag format version '" + printable(text.substr(9, n - 10)) +
                     "' is not supported (only 2.0)");
  file.fail(0, "not a ROS bag: the file does not start with \"#ROSBAG V2.0\"");
}

inline BagHeader read_bag_header(const FileReader& file) {
  std::vector<unsigned char> header;
  const auto r = read_record(file, kMagicSize, header, "bag header");
  const FieldList f(header.data(), header.size(), file_place(file), r.header_at);
  if (f.op() != static_cast<std::uint8_t>(Op::bag_header))
    file.fail(r.pos, "expected the bag header record, found a " + op_name(f.op()) + " record");
  BagHeader h{f.u64("index_pos"), f.u32("conn_count"), f.u32("chunk_count"), r.end()};
  if (h.index_pos != 0 && h.index_pos < h.end)
    f.fail("index_pos " + std::to_string(h.index_pos) + " points inside the bag header");
  return h;
}

/// A file cut before its index: index_pos past the end, or at the end with records announced.
inline bool index_cut(const FileReader& file, const BagHeader& h) {
  if (h.index_pos > file.size()) return true;
  return h.index_pos == file.size() && (h.conn_count != 0 || h.chunk_count != 0);
}

}  // namespace ulc::bags::ros1
