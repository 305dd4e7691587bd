// MergedSource: several MessageSources read as one recording (the files of a split rosbag2 bag,
// or bags recorded side by side).
//
// Topics are merged by name: the types (and serialisations) must agree, counts add up, first/last
// times are the min/max, connections are the most any part has (a split bag repeats them). A cursor
// is a k-way merge of the parts' cursors by receive time; equal times come from the earlier part
// first. A part's cursor opens only once the merge reaches that part's first selected message time
// (from its topics()), and closes when exhausted, so a split bag whose files follow each other in
// time holds one or two files' cursors (and their chunks) at a time rather than all of them.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <queue>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ulc/bags/message_source.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

class MergedSource : public MessageSource {
 public:
  /// `part_names` (optional, one per part: the file names) are what errors cite.
  explicit MergedSource(std::vector<std::unique_ptr<MessageSource>> parts,
                        std::vector<std::string> part_names = {})
      : parts_(std::move(parts)), names_(std::move(part_names)) {
    for (std::size_t p = 0; p < parts_.size(); ++p)
      if (parts_[p] == nullptr)
        throw std::invalid_argument("MergedSource: part " + name_of(p) + " is null");
    merge_topics();
  }

  const std::vector<TopicInfo>& topics() const override { return topics_; }

  std::vector<std::string> warnings() const override {
    std::vector<std::string> all;
    for (const auto& part : parts_) {
      auto w = part->warnings();
      all.insert(all.end(), w.begin(), w.end());
    }
    return all;
  }

  std::unique_ptr<MessageCursor> cursor(const std::vector<std::size_t>& selected,
                                        TimeWindow window) const override;

  std::size_t part_count() const { return parts_.size(); }

 private:
  class Cursor;

  std::string name_of(std::size_t part) const {
    return part < names_.size() ? names_[part] : "part " + std::to_string(part);
  }

  void merge_topics() {
    std::map<std::string, std::pair<TopicInfo, std::size_t>> by_name;  // topic, first part
    for (std::size_t p = 0; p < parts_.size(); ++p)
      for (const TopicInfo& t : parts_[p]->topics()) add_topic(by_name, t, p);
    for (auto& entry : by_name) topics_.push_back(std::move(entry.second.first));
    part_to_merged_.resize(parts_.size());
    for (std::size_t p = 0; p < parts_.size(); ++p)
      for (const TopicInfo& t : parts_[p]->topics()) part_to_merged_[p].push_back(index_of(t.name));
  }

  void add_topic(std::map<std::string, std::pair<TopicInfo, std::size_t>>& by_name,
                 const TopicInfo& t, std::size_t part) const {
    auto found = by_name.find(t.name);
    if (found == by_name.end()) {
      by_name.emplace(t.name, std::make_pair(t, part));
      return;
    }
    TopicInfo& into = found->second.first;
    if (into.type != t.type || into.serialization != t.serialization)
      throw io::IoError(name_of(part), "",
                        "topic " + t.name + " has type " + t.type + " here but " + into.type +
                            " in " + name_of(found->second.second) +
                            (into.type == t.type ? " (another serialization)" : ""));
    if (t.message_count > 0) {
      const bool first = into.message_count == 0;
      into.first_time_ns = first ? t.first_time_ns : std::min(into.first_time_ns, t.first_time_ns);
      into.last_time_ns = first ? t.last_time_ns : std::max(into.last_time_ns, t.last_time_ns);
    }
    into.message_count += t.message_count;
    into.connections = std::max(into.connections, t.connections);  // a split bag repeats them
  }

  std::size_t index_of(const std::string& name) const {
    const auto it =
        std::lower_bound(topics_.begin(), topics_.end(), name,
                         [](const TopicInfo& t, const std::string& n) { return t.name < n; });
    return static_cast<std::size_t>(it - topics_.begin());
  }

  std::vector<std::unique_ptr<MessageSource>> parts_;
  std::vector<std::string> names_;
  std::vector<TopicInfo> topics_;
  std::vector<std::vector<std::size_t>> part_to_merged_;  ///< [part][part's topic] -> merged
};

class MergedSource::Cursor : public MessageCursor {
 public:
  Cursor(const MergedSource& source, const std::vector<std::size_t>& selected, TimeWindow window)
      : source_(source), window_(window), parts_(source.parts_.size()) {
    std::vector<bool> wanted(source.topics_.size(), false);
    for (const std::size_t index : selected) {
      if (index >= wanted.size())
        throw std::out_of_range("MergedSource::cursor: topic index " + std::to_string(index) +
                                " out of range (" + std::to_string(wanted.size()) + " topics)");
      wanted[index] = true;
    }
    for (std::size_t p = 0; p < parts_.size(); ++p) plan_part(p, wanted);
    std::sort(waiting_.begin(), waiting_.end(), [this](std::size_t a, std::size_t b) {
      return std::make_pair(parts_[a].opens_at, a) > std::make_pair(parts_[b].opens_at, b);
    });  // descending: the next part to open is at the back
  }

  bool next(MessageView& out) override {
    if (last_ != kNone) advance(last_);
    last_ = kNone;
    open_due_parts();
    if (ready_.empty()) return false;
    const std::size_t p = ready_.top().second;
    ready_.pop();
    out = parts_[p].pending;
    out.topic = source_.part_to_merged_[p].at(out.topic);
    last_ = p;
    return true;
  }

 private:
  static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

  struct Part {
    std::vector<std::size_t> selected;  ///< the part's own topic indexes
    std::int64_t opens_at = 0;          ///< no selected message of the part comes earlier
    std::unique_ptr<MessageCursor> cursor;
    MessageView pending;
  };

  /// The part's selected topics, and when its first selected message can come. Topics listed
  /// without messages give no bound: such a part opens at once (and likely yields nothing).
  void plan_part(std::size_t p, const std::vector<bool>& wanted) {
    Part& part = parts_[p];
    const auto& topics = source_.parts_[p]->topics();
    bool bounded = true;
    std::int64_t first = std::numeric_limits<std::int64_t>::max();
    std::int64_t last = std::numeric_limits<std::int64_t>::min();
    for (std::size_t t = 0; t < topics.size(); ++t) {
      if (!wanted[source_.part_to_merged_[p][t]]) continue;
      part.selected.push_back(t);
      if (topics[t].message_count == 0) {
        bounded = false;
      } else {
        first = std::min(first, topics[t].first_time_ns);
        last = std::max(last, topics[t].last_time_ns);
      }
    }
    if (part.selected.empty()) return;
    part.opens_at = bounded ? std::max(first, window_.begin_ns) : window_.begin_ns;
    if (bounded && (part.opens_at >= window_.end_ns || last < window_.begin_ns))
      return;  // nothing of it in the window
    waiting_.push_back(p);
  }

  /// Opens every waiting part whose first message may come before (or with) the earliest pending.
  void open_due_parts() {
    while (!waiting_.empty()) {
      const std::size_t p = waiting_.back();
      if (!ready_.empty() && parts_[p].opens_at > ready_.top().first) return;
      waiting_.pop_back();
      parts_[p].cursor = source_.parts_[p]->cursor(parts_[p].selected, window_);
      advance(p);
    }
  }

  /// Pulls the part's next message into `pending` (queued), or closes the part at its end.
  void advance(std::size_t p) {
    Part& part = parts_[p];
    if (part.cursor->next(part.pending)) {
      ready_.emplace(part.pending.time_ns, p);
    } else {
      part.cursor.reset();
    }
  }

  using Entry = std::pair<std::int64_t, std::size_t>;  // time, part: ties to the earlier part
  const MergedSource& source_;
  TimeWindow window_;
  std::vector<Part> parts_;
  std::vector<std::size_t> waiting_;  ///< parts not opened yet, next to open at the back
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> ready_;
  std::size_t last_ = kNone;  ///< the part whose message the caller holds: advanced on next()
};

inline std::unique_ptr<MessageCursor> MergedSource::cursor(const std::vector<std::size_t>& selected,
                                                           TimeWindow window) const {
  return std::make_unique<Cursor>(*this, selected, window);
}

}  // namespace ulc::bags
