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
// an io::IoError naming the file, the byte and the problem.
//
// The parts: ros1/contents.hpp (connections, chunks, index entries), ros1/bag_header.hpp,
// ros1/index_reader.hpp (opening a closed bag), ros1/linear_scan.hpp (opening an unfinished one),
// ros1/cursor.hpp (reading).
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/bags/message_span.hpp"
#include "ulc/bags/ros1/bag_header.hpp"
#include "ulc/bags/ros1/contents.hpp"
#include "ulc/bags/ros1/cursor.hpp"
#include "ulc/bags/ros1/index_reader.hpp"
#include "ulc/bags/ros1/linear_scan.hpp"

namespace ulc::bags {

class Ros1Bag : public MessageSource {
 public:
  explicit Ros1Bag(const std::filesystem::path& file) : file_(file) {
    ros1::check_magic(file_);
    const ros1::BagHeader h = ros1::read_bag_header(file_);
    if (h.index_pos == 0) {
      warnings_.push_back(
          "no index (the bag header's index_pos is 0: an unfinished recording): read by a "
          "linear scan");
      ros1::LinearScan(file_, contents_, warnings_).scan(h.end);
    } else if (ros1::index_cut(file_, h)) {
      // A closed recording that lost its end: a damaged file, not an unfinished one.
      file_.fail(file_.size(), "truncated bag: the bag header puts the index at byte " +
                                   std::to_string(h.index_pos) + ", the file ends at byte " +
                                   std::to_string(file_.size()));
    } else {
      ros1::IndexReader(file_, contents_).read(h);
    }
    build_topics();
  }

  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::vector<std::string> warnings() const override { return warnings_; }

  std::unique_ptr<MessageCursor> cursor(const std::vector<std::size_t>& selected,
                                        TimeWindow window) const override {
    std::vector<bool> topic_wanted(topics_.size(), false);
    for (const std::size_t t : selected) {
      if (t >= topics_.size())
        throw std::out_of_range("Ros1Bag::cursor: topic index " + std::to_string(t) + ", " +
                                file_.name() + " has " + std::to_string(topics_.size()) +
                                " topics");
      topic_wanted[t] = true;
    }
    const auto& connections = contents_.connections;
    std::vector<bool> wanted(connections.size());
    for (std::size_t k = 0; k < connections.size(); ++k)
      wanted[k] = topic_wanted[connections[k].topic_index];
    return std::make_unique<ros1::Cursor>(file_, contents_,
                                          ros1::select_entries(file_, contents_, wanted, window));
  }

  /// True when the bag's index was read; false after a linear scan.
  bool indexed() const { return contents_.indexed; }
  const std::string& file() const { return file_.name(); }

 private:
  /// One TopicInfo per topic name, sorted by name, merging the connections that carry it.
  void build_topics() {
    auto& connections = contents_.connections;
    std::vector<std::size_t> order(connections.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return connections[a].topic < connections[b].topic;
    });
    for (const std::size_t k : order) {
      ros1::Connection& c = connections[k];
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
    MessageSpan span{t.message_count, t.first_time_ns, t.last_time_ns};
    span.merge(c.messages);
    t.message_count = span.count;
    t.first_time_ns = span.first_ns;
    t.last_time_ns = span.last_ns;
  }

  FileReader file_;
  ros1::Contents contents_;
  std::vector<TopicInfo> topics_;
  std::vector<std::string> warnings_;
};

}  // namespace ulc::bags
