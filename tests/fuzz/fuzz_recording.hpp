// Reads a whole recording the way `ulc` does, checking the MessageSource promises
// (ulc/bags/message_source.hpp) on every message: topic index in range, receive-time order,
// the selection and the time window respected. Cloud messages are decoded as well
// (ulc/bags/cloud_message.hpp), as the frame source would.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "fuzz_support.hpp"
#include "ulc/bags/cloud_message.hpp"
#include "ulc/bags/message_source.hpp"

namespace ulc_fuzz {

inline void decode_if_cloud(const ulc::bags::TopicInfo& topic, const ulc::bags::MessageView& m) {
  const auto type = ulc::bags::cloud_message_type(topic.type);
  if (!type) return;
  try {
    check_decoded(ulc::bags::decode_cloud_message(*type, topic, m).cloud);
  } catch (const ulc::io::IoError&) {
    // A malformed message inside a well-formed recording.
  }
}

/// Every message of `selected` in `window`; returns how many came out. `check_times`: require
/// receive-time order and times inside the window.
inline std::uint64_t read_selection(const ulc::bags::MessageSource& source,
                                    const std::vector<std::size_t>& selected,
                                    ulc::bags::TimeWindow window, bool check_times) {
  const auto& topics = source.topics();
  std::vector<bool> wanted(topics.size(), false);
  for (const std::size_t t : selected) wanted[t] = true;
  const auto cursor = source.cursor(selected, window);
  ulc::bags::MessageView m;
  std::int64_t last = std::numeric_limits<std::int64_t>::min();
  std::uint64_t count = 0;
  while (cursor->next(m)) {
    fuzz_require(m.topic < topics.size(), "message: topic index out of range");
    fuzz_require(wanted[m.topic], "message: a topic that was not selected");
    fuzz_require(!check_times || window.contains(m.time_ns),
                 "message: receive time outside the window");
    fuzz_require(!check_times || m.time_ns >= last, "message: receive times out of order");
    fuzz_require(m.size == 0 || m.data != nullptr, "message: bytes without data");
    last = m.time_ns;
    touch(m.data, m.size);
    decode_if_cloud(topics[m.topic], m);
    ++count;
  }
  return count;
}

/// All topics over all time, then the first topic over a window that cuts its first message.
inline void read_recording(const ulc::bags::MessageSource& source, bool check_times = true) {
  const auto& topics = source.topics();
  (void)source.warnings();
  std::vector<std::size_t> all(topics.size());
  for (std::size_t t = 0; t < all.size(); ++t) all[t] = t;
  read_selection(source, all, ulc::bags::TimeWindow{}, check_times);
  if (topics.empty() || topics[0].message_count == 0 ||
      topics[0].first_time_ns == std::numeric_limits<std::int64_t>::max())
    return;
  ulc::bags::TimeWindow window;
  window.begin_ns = topics[0].first_time_ns + 1;
  read_selection(source, {0}, window, check_times);
}

}  // namespace ulc_fuzz
