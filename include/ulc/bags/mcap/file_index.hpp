// What the MCAP reader knows of a file once opened (mcap_reader.hpp): its channels, schemas,
// chunks and the messages found outside indexed chunks; and the registration of Schema and
// Channel records, which may repeat but must agree.

#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/compression.hpp"
#include "ulc/bags/mcap_records.hpp"
#include "ulc/bags/message_source.hpp"

namespace ulc::bags::mcap {

/// Entry::chunk of a message outside any chunk.
constexpr std::uint32_t kLoose = std::numeric_limits<std::uint32_t>::max();

struct ChannelInfo {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string encoding;
  std::uint64_t record_offset = 0;  ///< where its Channel record is (for error messages)
  std::size_t topic_index = 0;
};

/// A Chunk record and where its MessageIndex records are.
struct ChunkRef {
  std::uint64_t offset = 0;  ///< of the Chunk record
  std::uint64_t length = 0;  ///< of the whole record, opcode and length included
  std::int64_t start_time = 0;
  std::int64_t end_time = 0;
  Codec codec = Codec::none;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint64_t index_offset = 0;  ///< the MessageIndex records right after the chunk
  std::uint64_t index_length = 0;
  std::vector<std::pair<std::uint16_t, std::uint64_t>> index_offsets;  ///< channel -> record
  bool indexed = false;  ///< messages listed through index_offsets (else found by the walk)
  bool seen = false;     ///< the data-section walk met it where the index says
};

/// One message: where it is and when. 24 bytes.
struct Entry {
  std::int64_t time = 0;
  std::uint64_t pos = 0;  ///< in the chunk's uncompressed records, or the file offset (kLoose)
  std::uint32_t chunk = kLoose;
  std::uint32_t topic = 0;  ///< topic index (channel slot while the file is being indexed)
};

/// Everything known about the file once opened.
struct FileIndex {
  std::vector<ChannelInfo> channels;
  std::vector<std::int32_t> channel_slot = std::vector<std::int32_t>(65536, -1);  ///< id -> slot
  std::map<std::uint16_t, SchemaRecord> schemas;
  std::vector<ChunkRef> chunks;
  std::vector<Entry> scanned;  ///< messages found by the walk (outside chunks, unindexed chunks)
  std::vector<TopicInfo> topics;
  std::vector<std::string> topic_problem;   ///< why a cursor cannot read a topic ("" = it can)
  std::vector<std::uint64_t> topic_offset;  ///< its first Channel record, for errors
  std::vector<std::string> warnings;

  std::int32_t slot_of(std::uint16_t channel_id) const { return channel_slot[channel_id]; }
};

/// Registers Schema and Channel records; a second record with an id already seen must agree.
class Declarations {
 public:
  explicit Declarations(FileIndex& index) : index_(index) {}

  void schema(const SchemaRecord& s, const Place& place, std::uint64_t pos) {
    if (s.id == 0) return;  // the specification: an id of zero is invalid, ignored
    const auto [it, added] = index_.schemas.emplace(s.id, s);
    if (!added && it->second.name != s.name)
      place.fail(pos, "Schema " + std::to_string(s.id) + " declared twice, as '" + it->second.name +
                          "' and as '" + s.name + "'");
  }

  void channel(const ChannelRecord& c, const Place& place, std::uint64_t pos) {
    std::int32_t& slot = index_.channel_slot[c.id];
    if (slot >= 0) {
      const ChannelInfo& old = index_.channels[static_cast<std::size_t>(slot)];
      if (old.topic != c.topic || old.encoding != c.message_encoding ||
          old.schema_id != c.schema_id)
        place.fail(pos, "Channel " + std::to_string(c.id) + " declared twice with different " +
                            "contents (topic '" + old.topic + "' and '" + c.topic + "')");
      return;
    }
    slot = static_cast<std::int32_t>(index_.channels.size());
    index_.channels.push_back(
        {c.id, c.schema_id, c.topic, c.message_encoding, place.offset_of(pos), 0});
  }

 private:
  FileIndex& index_;
};

}  // namespace ulc::bags::mcap
