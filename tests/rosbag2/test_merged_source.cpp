// MergedSource over hand-made in-memory sources: topic merging, time order, ties, clashes.
#include <catch2/catch.hpp>

#include "rosbag2_test_util.hpp"
#include "ulc/bags/merged_source.hpp"
#include "ulc/io/io_error.hpp"

namespace merged_source_test {

using namespace ulc::bags;
using rosbag2_test::Copied;

/// An in-memory MessageSource: messages given in time order, each one byte (its label).
class FakeSource : public MessageSource {
 public:
  struct Message {
    std::size_t topic;
    std::int64_t time_ns;
    unsigned char label;
  };
  FakeSource(std::vector<TopicInfo> topics, std::vector<Message> messages,
             std::vector<std::string> warnings = {})
      : topics_(std::move(topics)), messages_(std::move(messages)), warnings_(std::move(warnings)) {
    for (auto& t : topics_) t.message_count = 0;
    for (const auto& m : messages_) {
      TopicInfo& t = topics_[m.topic];
      if (t.message_count++ == 0) t.first_time_ns = m.time_ns;
      t.last_time_ns = m.time_ns;
    }
  }
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::vector<std::string> warnings() const override { return warnings_; }
  std::unique_ptr<MessageCursor> cursor(const std::vector<std::size_t>& selected,
                                        TimeWindow window) const override {
    ++cursors_opened;
    return std::make_unique<Cursor>(*this, selected, window);
  }
  mutable int cursors_opened = 0;

 private:
  class Cursor : public MessageCursor {
   public:
    Cursor(const FakeSource& s, std::vector<std::size_t> selected, TimeWindow w)
        : source_(s), selected_(std::move(selected)), window_(w) {}
    bool next(MessageView& out) override {
      while (i_ < source_.messages_.size()) {
        const Message& m = source_.messages_[i_++];
        if (!window_.contains(m.time_ns)) continue;
        if (std::find(selected_.begin(), selected_.end(), m.topic) == selected_.end()) continue;
        out.topic = m.topic;
        out.time_ns = m.time_ns;
        out.data = &m.label;
        out.size = 1;
        return true;
      }
      return false;
    }

   private:
    const FakeSource& source_;
    std::vector<std::size_t> selected_;
    TimeWindow window_;
    std::size_t i_ = 0;
  };

  std::vector<TopicInfo> topics_;
  std::vector<Message> messages_;
  std::vector<std::string> warnings_;
};

inline TopicInfo topic(const std::string& name, const std::string& type = "std_msgs/msg/String") {
  TopicInfo t;
  t.name = name;
  t.type = type;
  t.serialization = Serialization::cdr;
  return t;
}

/// The labels of what the source yields.
inline std::string labels(const MessageSource& s, const std::vector<std::size_t>& selected,
                          TimeWindow window = {}) {
  std::string out;
  for (const auto& m : rosbag2_test::read_all(s, selected, window))
    out += static_cast<char>(m.data.at(0));
  return out;
}

TEST_CASE("MergedSource: overlapping parts merge by time, ties to the earlier part", "[rosbag2]") {
  std::vector<std::unique_ptr<MessageSource>> parts;
  // Part 0 topics (/b, /a), part 1 topics (/a, /c): /a is shared.
  parts.push_back(std::make_unique<FakeSource>(
      std::vector<TopicInfo>{topic("/b"), topic("/a")},
      std::vector<FakeSource::Message>{{0, 10, 'a'}, {1, 20, 'b'}, {0, 30, 'c'}, {1, 40, 'd'}},
      std::vector<std::string>{"w0"}));
  parts.push_back(std::make_unique<FakeSource>(
      std::vector<TopicInfo>{topic("/a"), topic("/c")},
      std::vector<FakeSource::Message>{{0, 5, 'E'}, {1, 20, 'F'}, {0, 30, 'G'}, {1, 50, 'H'}},
      std::vector<std::string>{"w1", "w2"}));
  const MergedSource merged(std::move(parts));
  const auto& t = merged.topics();
  REQUIRE(t.size() == 3);
  CHECK(t[0].name == "/a");
  CHECK(t[0].message_count == 4);
  CHECK(t[0].first_time_ns == 5);
  CHECK(t[0].last_time_ns == 40);
  CHECK(t[0].connections == 1);  // the same topic in two parts: one connection each
  CHECK(t[1].name == "/b");
  CHECK(t[1].message_count == 2);
  CHECK(t[1].connections == 1);
  CHECK(t[2].name == "/c");
  CHECK(t[2].last_time_ns == 50);
  CHECK(merged.warnings() == std::vector<std::string>{"w0", "w1", "w2"});

  CHECK(labels(merged, {0, 1, 2}) == "EabFcGdH");
  CHECK(labels(merged, {0}) == "EbGd");
  CHECK(labels(merged, {1, 2}) == "aFcH");
  CHECK(labels(merged, {0, 1, 2}, TimeWindow{20, 40}) == "bFcG");
  CHECK(labels(merged, {}).empty());
  // Topic indexes in the views are the merged ones.
  for (const auto& m : rosbag2_test::read_all(merged, {0, 1, 2}))
    CHECK(((m.topic == "/a") ==
           (m.data[0] == 'E' || m.data[0] == 'G' || m.data[0] == 'b' || m.data[0] == 'd')));
  CHECK_THROWS_AS(merged.cursor({3}, {}), std::out_of_range);
}

TEST_CASE("MergedSource: parts following each other open one at a time", "[rosbag2]") {
  std::vector<std::unique_ptr<MessageSource>> parts;
  std::vector<const FakeSource*> fakes;
  for (int p = 0; p < 4; ++p) {
    std::vector<FakeSource::Message> messages;
    for (int i = 0; i < 3; ++i)
      messages.push_back({0, p * 100 + i * 10, static_cast<unsigned char>('a' + p * 3 + i)});
    auto part = std::make_unique<FakeSource>(std::vector<TopicInfo>{topic("/x")}, messages);
    fakes.push_back(part.get());
    parts.push_back(std::move(part));
  }
  const MergedSource merged(std::move(parts));
  auto c = merged.cursor({0}, {});
  MessageView m;
  REQUIRE(c->next(m));
  CHECK(fakes[0]->cursors_opened == 1);
  CHECK(fakes[1]->cursors_opened == 0);  // its first message (100) is later than pending ones
  CHECK(fakes[3]->cursors_opened == 0);
  std::string all(1, static_cast<char>(*m.data));
  while (c->next(m)) all += static_cast<char>(*m.data);
  CHECK(all == "abcdefghijkl");
  // A window past the first parts never opens them.
  CHECK(labels(merged, {0}, TimeWindow{200, 1000}) == "ghijkl");
  CHECK(fakes[0]->cursors_opened == 1);
  CHECK(fakes[1]->cursors_opened == 1);
}

TEST_CASE("MergedSource: a type clash is an IoError naming the part", "[rosbag2]") {
  std::vector<std::unique_ptr<MessageSource>> parts;
  parts.push_back(std::make_unique<FakeSource>(std::vector<TopicInfo>{topic("/a", "x/msg/A")},
                                               std::vector<FakeSource::Message>{}));
  parts.push_back(std::make_unique<FakeSource>(std::vector<TopicInfo>{topic("/a", "x/msg/B")},
                                               std::vector<FakeSource::Message>{}));
  try {
    MergedSource merged(std::move(parts), {"one.db3", "two.db3"});
    FAIL("no error");
  } catch (const ulc::io::IoError& e) {
    CHECK(e.file() == "two.db3");
    CHECK_THAT(e.reason(), Catch::Contains("x/msg/A") && Catch::Contains("one.db3"));
  }
}

TEST_CASE("MergedSource: no parts, and topics without messages", "[rosbag2]") {
  const MergedSource none({});
  CHECK(none.topics().empty());
  CHECK(labels(none, {}).empty());

  std::vector<std::unique_ptr<MessageSource>> parts;
  parts.push_back(std::make_unique<FakeSource>(std::vector<TopicInfo>{topic("/e")},
                                               std::vector<FakeSource::Message>{}));
  parts.push_back(std::make_unique<FakeSource>(std::vector<TopicInfo>{topic("/e")},
                                               std::vector<FakeSource::Message>{{0, 7, 'z'}}));
  const MergedSource merged(std::move(parts));
  REQUIRE(merged.topics().size() == 1);
  CHECK(merged.topics()[0].message_count == 1);
  CHECK(merged.topics()[0].first_time_ns == 7);
  CHECK(merged.topics()[0].last_time_ns == 7);
  CHECK(labels(merged, {0}) == "z");
}

}  // namespace merged_source_test
