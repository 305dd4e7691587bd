// Helpers of the ROS 1 bag tests: temporary folders, a small planned bag, reading everything.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <vector>

#include "../support/temp_dir.hpp"
#include "ulc/bags/ros1_bag.hpp"
#include "ulc/bags/ros1_bag_writer.hpp"

namespace ros1_test {

namespace fs = std::filesystem;
using Bytes = std::vector<unsigned char>;
using ulc::bags::Codec;

/// A fresh folder under the system temp dir (tests/support/temp_dir.hpp).
struct TempDir : ulc_test::TempDir {
  TempDir() : ulc_test::TempDir("ulc_ros1_bag_test") {}
};

/// One message as written or read: comparable as a whole.
struct Message {
  std::string topic;
  std::int64_t time_ns = 0;
  Bytes data;
  bool operator==(const Message& o) const {
    return topic == o.topic && time_ns == o.time_ns && data == o.data;
  }
  bool operator<(const Message& o) const {
    return std::tie(topic, time_ns, data) < std::tie(o.topic, o.time_ns, o.data);
  }
};

inline std::vector<std::size_t> all_topics(const ulc::bags::MessageSource& bag) {
  std::vector<std::size_t> all(bag.topics().size());
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = k;
  return all;
}

inline std::size_t topic_index(const ulc::bags::MessageSource& bag, const std::string& name) {
  const auto& t = bag.topics();
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k].name == name) return k;
  FAIL("no topic " << name);
  return 0;
}

inline std::vector<Message> read_messages(const ulc::bags::MessageSource& bag,
                                          const std::vector<std::size_t>& selected,
                                          ulc::bags::TimeWindow window = {}) {
  std::vector<Message> out;
  bag.read(selected, window, [&](const ulc::bags::MessageView& m) {
    out.push_back({bag.topics()[m.topic].name, m.time_ns, Bytes(m.data, m.data + m.size)});
    return true;
  });
  return out;
}

inline std::vector<Message> read_all(const ulc::bags::MessageSource& bag) {
  return read_messages(bag, all_topics(bag));
}

inline Bytes file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void write_bytes(const fs::path& p, const Bytes& b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

inline ulc::bags::Ros1Connection string_connection(const std::string& topic,
                                                   const std::string& callerid = "/talker") {
  return {topic,           "std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1",
          "string data\n", callerid,          false};
}

/// A small bag of two topics over several chunks, some messages out of time order.
inline std::vector<Message> write_small_bag(const fs::path& file, Codec codec, bool index) {
  ulc::bags::Ros1BagWriter w(file, {codec, 96, index});
  const std::uint32_t a = w.add_connection(string_connection("/a"));
  const std::uint32_t b = w.add_connection(string_connection("/b"));
  std::vector<Message> written;
  for (int i = 0; i < 8; ++i) {
    const std::int64_t t = 1000000000LL * (10 + i) - (i == 5 ? 3000000000LL : 0);
    Bytes data(static_cast<std::size_t>(i * 5));
    for (std::size_t k = 0; k < data.size(); ++k) data[k] = static_cast<unsigned char>(i + k);
    w.write(i % 3 == 0 ? b : a, t, data.data(), data.size());
    written.push_back({i % 3 == 0 ? "/b" : "/a", t, data});
  }
  w.close();
  return written;
}

/// Expects an io::IoError naming the file and a byte.
inline void check_io_error(const ulc::io::IoError& e, const fs::path& file) {
  const std::string what = e.what();
  INFO(what);
  CHECK(what.find(file.string()) != std::string::npos);
  CHECK(what.find("byte ") != std::string::npos);
}

}  // namespace ros1_test
