// Reading the selected messages of an MCAP file (mcap_reader.hpp, "Reading"): the entries listed
// from the MessageIndex records and the walk, in time order, and a cursor that decompresses each
// chunk when first needed and keeps it until its last listed message has been read.

#pragma once

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/mcap/chunks.hpp"
#include "ulc/bags/mcap/file_index.hpp"
#include "ulc/bags/mcap_records.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/io/endian.hpp"

namespace ulc::bags::mcap {

/// Decompressed chunks a cursor keeps at once (chunks overlapping in time).
constexpr std::size_t kMaxCachedChunks = 8;

/// The selected messages in (time, file position) order.
inline std::vector<Entry> collect_entries(const FileReader& file, const FileIndex& index,
                                          const std::vector<std::size_t>& selected,
                                          const TimeWindow& window) {
  std::vector<char> topic_wanted(index.topics.size(), 0);
  for (std::size_t t : selected) {
    if (t >= index.topics.size())
      throw std::out_of_range("MCAP cursor: topic index " + std::to_string(t) + " of " +
                              std::to_string(index.topics.size()));
    if (!index.topic_problem[t].empty()) file.fail(index.topic_offset[t], index.topic_problem[t]);
    topic_wanted[t] = 1;
  }
  std::vector<Entry> entries;
  for (const Entry& e : index.scanned)
    if (topic_wanted[e.topic] && window.contains(e.time)) entries.push_back(e);
  std::vector<unsigned char> buf;
  const auto wanted = [&](std::int32_t slot) {
    return slot >= 0 && topic_wanted[index.channels[static_cast<std::size_t>(slot)].topic_index];
  };
  for (std::size_t k = 0; k < index.chunks.size(); ++k) {
    const ChunkRef& c = index.chunks[k];
    if (!c.indexed || c.end_time < window.begin_ns || c.start_time >= window.end_ns) continue;
    for_each_message_index(
        file, index, c, buf, wanted,
        [&](std::int32_t slot, const unsigned char* e, std::uint64_t n, std::uint64_t at) {
          const auto topic = static_cast<std::uint32_t>(
              index.channels[static_cast<std::size_t>(slot)].topic_index);
          for (std::uint64_t i = 0; i < n; ++i, e += kIndexEntrySize) {
            const auto t = static_cast<std::int64_t>(io::load_le<std::uint64_t>(e));
            const std::uint64_t pos = io::load_le<std::uint64_t>(e + 8);
            if (pos > c.uncompressed_size ||
                c.uncompressed_size - pos < kRecordHeaderSize + kMessageFixedSize)
              file.fail(at, "MessageIndex entry points to byte " + std::to_string(pos) +
                                " of a chunk whose records hold " +
                                std::to_string(c.uncompressed_size) + " bytes");
            if (window.contains(t))
              entries.push_back({t, pos, static_cast<std::uint32_t>(k), topic});
          }
        });
  }
  const auto container = [&](const Entry& e) {
    return e.chunk == kLoose ? e.pos : index.chunks[e.chunk].offset;
  };
  const auto before = [&](const Entry& a, const Entry& b) {
    if (a.time != b.time) return a.time < b.time;
    const std::uint64_t ca = container(a), cb = container(b);
    return ca != cb ? ca < cb : a.pos < b.pos;
  };
  if (!std::is_sorted(entries.begin(), entries.end(), before))
    std::sort(entries.begin(), entries.end(), before);
  return entries;
}

class Cursor : public MessageCursor {
 public:
  Cursor(const FileReader& file, const FileIndex& index, std::vector<Entry> entries)
      : file_(file), index_(index), entries_(std::move(entries)), loose_(file) {
    last_use_.assign(index.chunks.size(), 0);
    for (std::size_t i = 0; i < entries_.size(); ++i)
      if (entries_[i].chunk != kLoose) last_use_[entries_[i].chunk] = i;
    slots_.reserve(kMaxCachedChunks);
  }

  bool next(MessageView& out) override {
    if (next_ == entries_.size()) return false;
    const std::size_t i = next_++;
    const Entry& e = entries_[i];
    if (e.chunk == kLoose) {
      read_loose(e, out);
    } else {
      Slot& s = slot_for(e.chunk);
      read_chunked(e, s, out);
      if (last_use_[e.chunk] == i) s.chunk = kLoose;  // free for the next chunk
    }
    return true;
  }

 private:
  struct Slot {
    std::uint32_t chunk = kLoose;  ///< kLoose: free
    std::vector<unsigned char> data;
    const unsigned char* records = nullptr;
    std::uint64_t size = 0;
    std::uint64_t records_offset = 0;  ///< file offset of the records (uncompressed chunks)
    std::uint64_t used = 0;
  };

  Slot& slot_for(std::uint32_t chunk) {
    ++clock_;
    for (Slot& s : slots_)
      if (s.chunk == chunk) {
        s.used = clock_;
        return s;
      }
    Slot* pick = nullptr;
    for (Slot& s : slots_)
      if (s.chunk == kLoose) pick = &s;
    if (!pick && slots_.size() < kMaxCachedChunks) pick = &slots_.emplace_back();
    if (!pick)
      pick = &*std::min_element(slots_.begin(), slots_.end(),
                                [](const Slot& a, const Slot& b) { return a.used < b.used; });
    pick->chunk = kLoose;
    load(chunk, *pick);
    pick->chunk = chunk;
    pick->used = clock_;
    return *pick;
  }

  void load(std::uint32_t chunk, Slot& s) {
    const ChunkRef& c = index_.chunks[chunk];
    std::vector<unsigned char>& record = c.codec == Codec::none ? s.data : raw_;
    file_.read_at(c.offset, c.length, record, "Chunk record");
    const ChunkRecords r = open_chunk(record.data(), c.length, c.offset, file_.name(), s.data);
    if (r.header.compression != c.compression || r.header.records_size != c.compressed_size ||
        r.header.uncompressed_size != c.uncompressed_size)
      file_.fail(c.offset, "Chunk record (compression '" + r.header.compression + "', " +
                               std::to_string(r.header.records_size) + " -> " +
                               std::to_string(r.header.uncompressed_size) +
                               " bytes) disagrees with its ChunkIndex ('" + c.compression + "', " +
                               std::to_string(c.compressed_size) + " -> " +
                               std::to_string(c.uncompressed_size) + " bytes)");
    s.records = r.data;
    s.size = r.size;
    s.records_offset = c.offset + kRecordHeaderSize + r.header.records_pos;
  }

  void read_chunked(const Entry& e, const Slot& s, MessageView& out) const {
    const ChunkRef& c = index_.chunks[e.chunk];
    const Place place = c.codec == Codec::none ? Place{file_.name(), s.records_offset}
                                               : Place{file_.name(), c.offset, true};
    if (e.pos > s.size || s.size - e.pos < kRecordHeaderSize)
      place.fail(e.pos, "message index points past the chunk's records");
    const RecordHeader rh = parse_record_header(s.records + e.pos);
    if (!is(rh.op, Op::message))
      place.fail(e.pos, "message index points to a " + op_name(rh.op) + " record, not a Message");
    if (rh.length > s.size - e.pos - kRecordHeaderSize)
      place.fail(e.pos, "Message record of " + std::to_string(rh.length) +
                            " bytes runs past the end of its chunk");
    const unsigned char* content = s.records + e.pos + kRecordHeaderSize;
    const MessageHeader m = parse_message(content, rh.length, place, e.pos + kRecordHeaderSize);
    check_matches(m, e, place, e.pos);
    fill(out, e, content, m, place.offset_of(e.pos));
  }

  void read_loose(const Entry& e, MessageView& out) {
    const Place place{file_.name(), e.pos};
    const RecordHeader rh = parse_record_header(loose_.get(e.pos, kRecordHeaderSize, "Message"));
    if (!is(rh.op, Op::message))
      place.fail(0, "expected a Message record, found " + op_name(rh.op));
    const unsigned char* content =
        loose_.get(e.pos, kRecordHeaderSize + rh.length, "Message record") + kRecordHeaderSize;
    const MessageHeader m = parse_message(content, rh.length, place, kRecordHeaderSize);
    check_matches(m, e, place, 0);
    fill(out, e, content, m, e.pos);
  }

  void check_matches(const MessageHeader& m, const Entry& e, const Place& place,
                     std::uint64_t pos) const {
    const std::int32_t slot = index_.slot_of(m.channel_id);
    if (slot < 0 || index_.channels[static_cast<std::size_t>(slot)].topic_index != e.topic)
      place.fail(pos, "Message of channel " + std::to_string(m.channel_id) +
                          " where the message index expects topic '" + index_.topics[e.topic].name +
                          "'");
    if (static_cast<std::int64_t>(m.log_time) != e.time)
      place.fail(pos, "Message log_time " + std::to_string(m.log_time) +
                          " differs from its message index's " + std::to_string(e.time));
  }

  void fill(MessageView& out, const Entry& e, const unsigned char* content, const MessageHeader& m,
            std::uint64_t offset) const {
    out.topic = e.topic;
    out.time_ns = e.time;
    out.data = content + kMessageFixedSize;
    out.size = static_cast<std::size_t>(m.data_size);
    out.file = &file_.name();
    out.offset = offset;
  }

  const FileReader& file_;
  const FileIndex& index_;
  std::vector<Entry> entries_;
  std::size_t next_ = 0;
  std::vector<std::size_t> last_use_;  ///< per chunk: its last entry
  std::vector<Slot> slots_;
  std::vector<unsigned char> raw_;  ///< a compressed Chunk record being decompressed
  ReadWindow loose_;
  std::uint64_t clock_ = 0;
};

}  // namespace ulc::bags::mcap
