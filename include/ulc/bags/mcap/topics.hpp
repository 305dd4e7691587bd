// The topics of an MCAP file (mcap_reader.hpp, "Topics"): one per topic name over its channels,
// with message counts and first / last times from the Statistics record and the fewest
// MessageIndex records that can hold them, or from every chunk's indexes without statistics.

#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/mcap/chunks.hpp"
#include "ulc/bags/mcap/file_index.hpp"
#include "ulc/bags/mcap_records.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/io/endian.hpp"

namespace ulc::bags::mcap {

/// Per-channel message counts and times while the file is being indexed.
struct ChannelTally {
  std::uint64_t count = 0;
  bool timed = false;
  std::int64_t first = 0;
  std::int64_t last = 0;

  void time(std::int64_t t) {
    first = timed ? std::min(first, t) : t;
    last = timed ? std::max(last, t) : t;
    timed = true;
  }
};

/// Fills index.topics, index.topic_problem and index.topic_offset from the channels, and turns
/// index.scanned's channel slots into topic indexes.
class TopicTable {
 public:
  TopicTable(const FileReader& file, FileIndex& index) : file_(file), index_(index) {}

  void build(const std::optional<StatisticsRecord>& statistics) {
    std::map<std::string, std::vector<std::size_t>> by_name;
    for (std::size_t s = 0; s < index_.channels.size(); ++s)
      by_name[index_.channels[s].topic].push_back(s);
    for (const auto& [name, slots] : by_name) add_topic(name, slots);
    tally_topics(statistics);
  }

 private:
  void add_topic(const std::string& name, const std::vector<std::size_t>& slots) {
    const ChannelInfo& first = index_.channels[slots.front()];
    TopicInfo t;
    t.name = name;
    t.type = schema_name(first);
    t.serialization = first.encoding == "ros1" ? Serialization::ros1 : Serialization::cdr;
    t.connections = slots.size();
    std::string problem;
    if (first.encoding != "cdr" && first.encoding != "ros1")
      problem = "message encoding '" + first.encoding + "' of topic '" + name +
                "' is not supported (ULC decodes cdr and ros1)";
    for (std::size_t s : slots) {
      index_.channels[s].topic_index = index_.topics.size();
      schema_name(index_.channels[s]);
      if (problem.empty() && index_.channels[s].encoding != first.encoding)
        problem = "the channels of topic '" + name + "' use different message encodings ('" +
                  first.encoding + "' and '" + index_.channels[s].encoding + "')";
    }
    index_.topics.push_back(t);
    index_.topic_problem.push_back(problem);
    index_.topic_offset.push_back(first.record_offset);
  }

  std::string schema_name(const ChannelInfo& c) const {
    if (c.schema_id == 0) return "";
    const auto it = index_.schemas.find(c.schema_id);
    if (it == index_.schemas.end())
      file_.fail(c.record_offset, "Channel " + std::to_string(c.id) + " refers to Schema " +
                                      std::to_string(c.schema_id) +
                                      ", which no Schema record declares");
    return it->second.name;
  }

  /// Message counts and first / last times per topic.
  void tally_topics(const std::optional<StatisticsRecord>& statistics) {
    std::vector<ChannelTally> tally(index_.channels.size());
    for (const Entry& e : index_.scanned) {
      ++tally[e.topic].count;
      tally[e.topic].time(e.time);
    }
    const bool counted = statistics && !statistics->channel_message_counts.empty();
    if (counted) {
      for (auto& t : tally) t.count = 0;
      for (const auto& [id, count] : statistics->channel_message_counts)
        if (index_.slot_of(id) >= 0)
          tally[static_cast<std::size_t>(index_.slot_of(id))].count = count;
      search_first_last(tally);
    } else {
      count_from_indexes(tally);
    }
    for (Entry& e : index_.scanned)
      e.topic = static_cast<std::uint32_t>(index_.channels[e.topic].topic_index);
    std::vector<ChannelTally> per_topic(index_.topics.size());
    for (std::size_t s = 0; s < tally.size(); ++s) {
      ChannelTally& t = per_topic[index_.channels[s].topic_index];
      t.count += tally[s].count;
      if (tally[s].timed) {
        t.time(tally[s].first);
        t.time(tally[s].last);
      }
    }
    for (std::size_t k = 0; k < per_topic.size(); ++k) {
      index_.topics[k].message_count = per_topic[k].count;
      index_.topics[k].first_time_ns = per_topic[k].first;
      index_.topics[k].last_time_ns = per_topic[k].last;
    }
  }

  /// Without per-channel statistics: every chunk's MessageIndex records give counts and times.
  void count_from_indexes(std::vector<ChannelTally>& tally) {
    for (const ChunkRef& c : index_.chunks) {
      if (!c.indexed) continue;
      for_each_message_index(
          file_, index_, c, scratch_, [](std::int32_t slot) { return slot >= 0; },
          [&](std::int32_t slot, const unsigned char* e, std::uint64_t n, std::uint64_t) {
            ChannelTally& t = tally[static_cast<std::size_t>(slot)];
            t.count += n;
            for (std::uint64_t k = 0; k < n; ++k)
              t.time(
                  static_cast<std::int64_t>(io::load_le<std::uint64_t>(e + k * kIndexEntrySize)));
          });
    }
  }

  /// With counts from the statistics: the first (last) time of a channel is in one of the chunks
  /// whose start (end) time is below (above) the best found so far; chunks sorted by start time
  /// (descending end time) stop being read as soon as none can do better.
  void search_first_last(std::vector<ChannelTally>& tally) {
    std::vector<const ChunkRef*> order;
    for (const ChunkRef& c : index_.chunks)
      if (c.indexed) order.push_back(&c);
    std::sort(order.begin(), order.end(),
              [](const ChunkRef* a, const ChunkRef* b) { return a->start_time < b->start_time; });
    std::vector<ChannelTally> best(tally.size());
    for (const ChunkRef* c : order)
      read_times_if(*c, best,
                    [&](const ChannelTally& b) { return !b.timed || c->start_time < b.first; });
    std::sort(order.begin(), order.end(),
              [](const ChunkRef* a, const ChunkRef* b) { return a->end_time > b->end_time; });
    for (const ChunkRef* c : order)
      read_times_if(*c, best,
                    [&](const ChannelTally& b) { return !b.timed || c->end_time > b.last; });
    for (std::size_t s = 0; s < tally.size(); ++s)
      if (best[s].timed) {
        tally[s].time(best[s].first);
        tally[s].time(best[s].last);
      }
  }

  template <typename Need>
  void read_times_if(const ChunkRef& c, std::vector<ChannelTally>& best, Need need) {
    for_each_message_index(
        file_, index_, c, scratch_,
        [&](std::int32_t slot) { return slot >= 0 && need(best[static_cast<std::size_t>(slot)]); },
        [&](std::int32_t slot, const unsigned char* e, std::uint64_t n, std::uint64_t) {
          for (std::uint64_t k = 0; k < n; ++k)
            best[static_cast<std::size_t>(slot)].time(
                static_cast<std::int64_t>(io::load_le<std::uint64_t>(e + k * kIndexEntrySize)));
        });
  }

  const FileReader& file_;
  FileIndex& index_;
  std::vector<unsigned char> scratch_;
};

}  // namespace ulc::bags::mcap
