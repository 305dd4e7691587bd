// The MCAP files rosbag2 wrote (../shared/data/bags/ros2/mcap, README there): topics, types and
// counts as documented, every message read back in time order.
#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <unistd.h>

#include "test_paths.hpp"
#include "ulc/bags/mcap_reader.hpp"

namespace mcap_real_test {

namespace fs = std::filesystem;
using ulc::bags::McapReader;
using ulc::bags::MessageView;

fs::path mcap_dir() {
  const fs::path bags = ulc_test::bags_dir();
  return bags.empty() ? fs::path() : bags / "ros2" / "mcap";
}

struct Expect {
  std::string type;
  std::uint64_t count;
};

/// Checks the topics against `want`, reads every message: times increase, counts and first /
/// last times agree with topics().
void check_file(const fs::path& file, const std::map<std::string, Expect>& want) {
  INFO(file.string());
  McapReader r(file);
  CHECK(r.warnings().empty());
  REQUIRE(r.topics().size() == want.size());
  std::vector<std::size_t> all;
  for (std::size_t k = 0; k < r.topics().size(); ++k) {
    const auto& t = r.topics()[k];
    REQUIRE(want.count(t.name) == 1);
    CHECK(t.type == want.at(t.name).type);
    CHECK(t.message_count == want.at(t.name).count);
    CHECK(t.serialization == ulc::bags::Serialization::cdr);
    CHECK(t.connections == 1);
    all.push_back(k);
  }
  std::vector<std::uint64_t> count(all.size(), 0);
  std::vector<std::int64_t> first(all.size(), 0), last(all.size(), 0);
  std::int64_t previous = std::numeric_limits<std::int64_t>::min();
  r.read(all, {}, [&](const MessageView& m) {
    CHECK(m.time_ns >= previous);
    previous = m.time_ns;
    if (count[m.topic]++ == 0) first[m.topic] = m.time_ns;
    last[m.topic] = m.time_ns;
    CHECK(m.size >= 4);  // a CDR encapsulation header at least
    CHECK(*m.file == file.string());
    return true;
  });
  for (std::size_t k = 0; k < all.size(); ++k) {
    CHECK(count[k] == r.topics()[k].message_count);
    CHECK(first[k] == r.topics()[k].first_time_ns);
    CHECK(last[k] == r.topics()[k].last_time_ns);
  }
}

struct Message {
  std::string topic;
  std::int64_t time;
  std::vector<unsigned char> data;
  bool operator==(const Message& o) const {
    return topic == o.topic && time == o.time && data == o.data;
  }
};

std::vector<Message> messages_of(const McapReader& r) {
  std::vector<std::size_t> all;
  for (std::size_t k = 0; k < r.topics().size(); ++k) all.push_back(k);
  std::vector<Message> out;
  r.read(all, {}, [&](const MessageView& m) {
    out.push_back({r.topics()[m.topic].name, m.time_ns, {m.data, m.data + m.size}});
    return true;
  });
  return out;
}

}  // namespace mcap_real_test

using namespace mcap_real_test;

TEST_CASE("mcap real files: talker", "[mcap][shared]") {
  ULC_SKIP_UNLESS(!mcap_dir().empty(), "../shared/data/bags is absent");
  const fs::path file = mcap_dir() / "talker" / "talker.mcap";
  check_file(file, {{"/topic", {"std_msgs/msg/String", 10}},
                    {"/rosout", {"rcl_interfaces/msg/Log", 10}},
                    {"/parameter_events", {"rcl_interfaces/msg/ParameterEvent", 0}}});
  McapReader r(file);
  // metadata.yaml: starting time 1585866235112411371, duration 4531096768 ns.
  std::int64_t first = std::numeric_limits<std::int64_t>::max(), last = 0;
  for (const auto& t : r.topics())
    if (t.message_count > 0) {
      first = std::min(first, t.first_time_ns);
      last = std::max(last, t.last_time_ns);
    }
  CHECK(first == 1585866235112411371);
  CHECK(last == 1585866235112411371 + 4531096768);
  CHECK(r.topics()[0].name == "/parameter_events");
  CHECK(r.topics()[0].first_time_ns == 0);
}

TEST_CASE("mcap real files: wbag, a bag split over five files", "[mcap][shared]") {
  ULC_SKIP_UNLESS(!mcap_dir().empty(), "../shared/data/bags is absent");
  const std::map<std::string, std::uint64_t> totals = {{"AAA", 804}, {"BBB", 742}, {"CCC", 742},
                                                       {"DDD", 753}, {"EEE", 804}, {"FFF", 772},
                                                       {"GGG", 731}, {"HHH", 726}};
  std::map<std::string, std::uint64_t> sum;
  std::uint64_t messages = 0;
  std::int64_t previous_last = 0;
  for (int k = 0; k < 5; ++k) {
    const fs::path file = mcap_dir() / "wbag" / ("wbag_" + std::to_string(k) + ".mcap");
    McapReader r(file);
    std::map<std::string, Expect> want;
    std::int64_t first = std::numeric_limits<std::int64_t>::max(), last = 0;
    for (const auto& t : r.topics()) {
      want[t.name] = {"std_msgs/msg/String", t.message_count};
      sum[t.name] += t.message_count;
      messages += t.message_count;
      first = std::min(first, t.first_time_ns);
      last = std::max(last, t.last_time_ns);
    }
    CHECK(want.size() == 8);
    check_file(file, want);
    CHECK(first >= previous_last);  // the split files follow each other in time
    previous_last = last;
  }
  CHECK(sum == totals);
  CHECK(messages == 6074);
}

TEST_CASE("mcap real files: convert_a and cdr_test", "[mcap][shared]") {
  ULC_SKIP_UNLESS(!mcap_dir().empty(), "../shared/data/bags is absent");
  check_file(mcap_dir() / "convert_a" / "rewriter_a_0.mcap",
             {{"a_empty", {"test_msgs/msg/Empty", 100}},
              {"b_basictypes", {"test_msgs/msg/BasicTypes", 50}}});
  const fs::path cdr = mcap_dir() / "cdr_test" / "cdr_test_0.mcap";
  check_file(cdr, {{"/test_topic", {"test_msgs/msg/BasicTypes", 3}},
                   {"/array_topic", {"test_msgs/msg/Arrays", 4}}});
  // metadata.yaml: starting time 1586406456763032325, duration 151137181 ns.
  McapReader r(cdr);
  CHECK(std::min(r.topics()[0].first_time_ns, r.topics()[1].first_time_ns) == 1586406456763032325);
  CHECK(std::max(r.topics()[0].last_time_ns, r.topics()[1].last_time_ns) ==
        1586406456763032325 + 151137181);
}

TEST_CASE("mcap real files read by a linear scan (Footer summary_start set to 0)",
          "[mcap][shared]") {
  ULC_SKIP_UNLESS(!mcap_dir().empty(), "../shared/data/bags is absent");
  const fs::path copy = fs::temp_directory_path() /
                        ("ulc_test_mcap_real_linear_" + std::to_string(::getpid()) + ".mcap");
  for (const char* name : {"talker/talker.mcap", "convert_a/rewriter_a_0.mcap",
                           "cdr_test/cdr_test_0.mcap", "wbag/wbag_2.mcap"}) {
    INFO(name);
    const fs::path original = mcap_dir() / name;
    fs::copy_file(original, copy, fs::copy_options::overwrite_existing);
    fs::permissions(copy, fs::perms::owner_read | fs::perms::owner_write);
    {
      std::fstream f(copy, std::ios::in | std::ios::out | std::ios::binary);
      f.seekp(static_cast<std::streamoff>(fs::file_size(copy) - 8 - 20));
      const char zeros[8] = {};
      f.write(zeros, 8);
    }
    McapReader indexed(original), scanned(copy);
    CHECK(scanned.warnings().size() == 1);
    const auto& a = indexed.topics();
    const auto& b = scanned.topics();
    // rosbag2 declares every channel inside the chunks too, those without messages included.
    REQUIRE(b.size() == a.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      CHECK(b[k].name == a[k].name);
      CHECK(b[k].type == a[k].type);
      CHECK(b[k].message_count == a[k].message_count);
      CHECK(b[k].first_time_ns == a[k].first_time_ns);
      CHECK(b[k].last_time_ns == a[k].last_time_ns);
      CHECK(b[k].connections == a[k].connections);
    }
    CHECK(messages_of(scanned) == messages_of(indexed));
  }
  fs::remove(copy);
}
