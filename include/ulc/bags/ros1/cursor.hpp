// Reading the selected messages of a ROS 1 bag (ros1_bag.hpp): their index entries in time order,
// and a cursor that decompresses each chunk when first needed and drops it after its last
// message, so chunks out of time order still give messages in time order.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/bags/ros1/contents.hpp"
#include "ulc/bags/ros1_records.hpp"

namespace ulc::bags::ros1 {

/// The index entries of the chosen connections inside `window`, in time order (ties in file
/// order).
inline std::vector<IndexEntry> select_entries(const FileReader& file, const Contents& contents,
                                              const std::vector<bool>& wanted, TimeWindow window) {
  std::vector<IndexEntry> entries;
  if (contents.indexed) {
    std::vector<unsigned char> buffer;
    for (std::size_t k = 0; k < contents.chunks.size(); ++k) {
      const auto chunk = static_cast<std::uint32_t>(k);
      contents.for_each_index_entry(
          file, contents.chunks[k], buffer,
          [&](std::size_t conn, std::int64_t t, std::uint32_t offset) {
            if (wanted[conn] && window.contains(t))
              entries.push_back({t, chunk, offset, static_cast<std::uint32_t>(conn)});
          });
    }
  } else {
    for (const IndexEntry& e : contents.scanned)
      if (wanted[e.connection] && window.contains(e.time_ns)) entries.push_back(e);
  }
  std::sort(entries.begin(), entries.end(), [](const IndexEntry& a, const IndexEntry& b) {
    if (a.time_ns != b.time_ns) return a.time_ns < b.time_ns;
    if (a.chunk != b.chunk) return a.chunk < b.chunk;
    return a.offset < b.offset;
  });
  return entries;
}

/// Walks the sorted index entries of a selection, keeping the decompressed chunks that later
/// entries still need (at most kMaxOpenChunks; beyond that the one needed last is dropped and
/// decompressed again when its turn comes).
class Cursor : public MessageCursor {
 public:
  static constexpr std::size_t kMaxOpenChunks = 8;

  Cursor(const FileReader& file, const Contents& contents, std::vector<IndexEntry> entries)
      : file_(file),
        contents_(contents),
        entries_(std::move(entries)),
        last_use_(contents.chunks.size(), 0) {
    for (std::size_t k = 0; k < entries_.size(); ++k) last_use_[entries_[k].chunk] = k;
  }

  bool next(MessageView& out) override {
    if (next_ >= entries_.size()) return false;
    const IndexEntry& e = entries_[next_];
    const Chunk& c = contents_.chunks[e.chunk];
    const std::vector<unsigned char>& data = chunk(e.chunk);
    const Place place = chunk_place(file_, c);
    const auto r = record_in_buffer(data.data(), data.size(), e.offset, place, "chunk");
    const FieldList f(data.data() + r.header_at, r.header_size, place, r.header_at);
    if (f.op() != static_cast<std::uint8_t>(Op::message_data))
      place.fail(e.offset,
                 "the index points to a " + op_name(f.op()) + " record, expected message data");
    const Connection& conn = contents_.connections[e.connection];
    if (f.u32("conn") != conn.id || f.time("time") != e.time_ns)
      place.fail(e.offset,
                 "the message data record does not match its index entry "
                 "(connection " +
                     std::to_string(conn.id) + ", time " + std::to_string(e.time_ns) + " ns)");
    out.topic = conn.topic_index;
    out.time_ns = e.time_ns;
    out.data = data.data() + r.data_at;
    out.size = static_cast<std::size_t>(r.data_size);
    out.file = &file_.name();
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
    load_chunk(file_, contents_.chunks[c], s.data, packed_);
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

  const FileReader& file_;
  const Contents& contents_;
  std::vector<IndexEntry> entries_;
  std::vector<std::size_t> last_use_;  ///< per chunk: the last entry that reads it
  std::size_t next_ = 0;
  std::vector<Slot> slots_;
  std::vector<std::vector<unsigned char>> spare_;
  std::vector<unsigned char> packed_;
};

}  // namespace ulc::bags::ros1
