// Opening an MCAP file (mcap_reader.hpp, "Opening"): the magic and Footer at its ends, then its
// summary and a walk of its data section, or a linear scan where there is no summary; the topics
// and their counts last.

#pragma once

#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/mcap/data_walk.hpp"
#include "ulc/bags/mcap/file_index.hpp"
#include "ulc/bags/mcap/summary.hpp"
#include "ulc/bags/mcap/topics.hpp"
#include "ulc/bags/mcap_records.hpp"

namespace ulc::bags::mcap {

/// Opens the file: reads its summary or scans its data section, fills a FileIndex.
class IndexBuilder {
 public:
  IndexBuilder(const FileReader& file, FileIndex& index) : file_(file), index_(index) {}

  void build() {
    check_leading_magic();
    const auto footer = read_tail();
    if (!footer)
      file_.fail(file_.size(),
                 "truncated MCAP file: no Footer and closing magic at its end (cut short, or a "
                 "recording that was never closed)");
    DataWalk walk(file_, index_);
    std::optional<StatisticsRecord> statistics;
    if (footer->summary_start != 0) {
      statistics = SummaryReader(file_, index_, footer_offset_).read(*footer);
      walk.walk(footer->summary_start, /*check_crc=*/false);
      check_indexed_chunks_seen();
    } else {
      index_.warnings.push_back(
          "no summary section (Footer summary_start is 0): messages indexed by a linear scan of "
          "the data section");
      walk.walk(footer_offset_, /*check_crc=*/true);
    }
    append_scanned_chunks(walk.take_unindexed());
    TopicTable(file_, index_).build(statistics);
  }

 private:
  void check_leading_magic() {
    if (file_.size() < kMagicSize)
      file_.fail(0, "not an MCAP file: " + std::to_string(file_.size()) +
                        " bytes, fewer than the 8-byte magic");
    unsigned char m[kMagicSize];
    file_.read_into(0, m, kMagicSize, "magic");
    if (std::memcmp(m, kMagic.data(), 5) != 0) file_.fail(0, "not an MCAP file: no magic");
    if (std::memcmp(m, kMagic.data(), kMagicSize) != 0)
      file_.fail(5, "unsupported MCAP major version '" + std::string(1, char(m[5])) +
                        "' (ULC reads version 0)");
  }

  /// The Footer when the file ends with Footer and magic; nullopt for a file cut short.
  std::optional<FooterRecord> read_tail() {
    constexpr std::uint64_t tail = kRecordHeaderSize + kFooterContentSize + kMagicSize;
    if (file_.size() < kMagicSize + tail) return std::nullopt;
    unsigned char t[tail];
    footer_offset_ = file_.size() - tail;
    file_.read_into(footer_offset_, t, tail, "Footer");
    const RecordHeader rh = parse_record_header(t);
    if (!is(rh.op, Op::footer) || rh.length != kFooterContentSize ||
        std::memcmp(t + tail - kMagicSize, kMagic.data(), kMagicSize) != 0)
      return std::nullopt;
    return parse_footer(t + kRecordHeaderSize);
  }

  /// Every indexed chunk must be where the walk found a Chunk record, and every MessageIndex must
  /// belong to a declared channel.
  void check_indexed_chunks_seen() {
    for (const ChunkRef& c : index_.chunks)
      if (!c.seen)
        file_.fail(c.offset, "a ChunkIndex points here, but no Chunk record starts at this byte");
    for (const ChunkRef& c : index_.chunks)
      for (const auto& [id, offset] : c.index_offsets)
        if (index_.slot_of(id) < 0)
          file_.fail(offset, "MessageIndex of channel " + std::to_string(id) +
                                 ", which no Channel record of the summary declares");
  }

  /// The chunks the walk scanned go after the indexed ones; their entries are renumbered.
  void append_scanned_chunks(std::vector<ChunkRef> scanned) {
    const auto base = static_cast<std::uint32_t>(index_.chunks.size());
    for (Entry& e : index_.scanned)
      if (e.chunk != kLoose) e.chunk += base;
    for (ChunkRef& c : scanned) index_.chunks.push_back(std::move(c));
  }

  const FileReader& file_;
  FileIndex& index_;
  std::uint64_t footer_offset_ = 0;
};

}  // namespace ulc::bags::mcap
