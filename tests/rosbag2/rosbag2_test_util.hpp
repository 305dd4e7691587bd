// Helpers shared by the rosbag2 tests: a temporary folder and a reader that copies messages out.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "ulc/bags/message_source.hpp"

namespace rosbag2_test {

/// A folder under the system temp directory, unique to this process, removed on destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    static int counter = 0;
    path_ =
        std::filesystem::temp_directory_path() / ("ulc_test_rosbag2_" + std::to_string(::getpid()) +
                                                  "_" + tag + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// A message copied out of a cursor.
struct Copied {
  std::string topic;
  std::int64_t time_ns = 0;
  std::vector<unsigned char> data;
  bool operator==(const Copied& o) const {
    return topic == o.topic && time_ns == o.time_ns && data == o.data;
  }
};

inline std::vector<Copied> read_all(const ulc::bags::MessageSource& source,
                                    const std::vector<std::size_t>& selected,
                                    ulc::bags::TimeWindow window = {}) {
  std::vector<Copied> out;
  source.read(selected, window, [&](const ulc::bags::MessageView& m) {
    out.push_back(Copied{source.topics().at(m.topic).name, m.time_ns,
                         std::vector<unsigned char>(m.data, m.data + m.size)});
    return true;
  });
  return out;
}

inline std::vector<std::size_t> all_topics(const ulc::bags::MessageSource& source) {
  std::vector<std::size_t> all(source.topics().size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return all;
}

/// The index of topic `name` in source.topics(), or the topic count when absent.
inline std::size_t topic_index(const ulc::bags::MessageSource& source, const std::string& name) {
  const auto& topics = source.topics();
  for (std::size_t i = 0; i < topics.size(); ++i)
    if (topics[i].name == name) return i;
  return topics.size();
}

}  // namespace rosbag2_test
