// How many messages a topic, a connection or a file holds, and the span of their times: what a
// reader reports per topic and what a writer records in a recording's metadata.
#pragma once

#include <algorithm>
#include <cstdint>

namespace ulc::bags {

struct MessageSpan {
  std::uint64_t count = 0;
  std::int64_t first_ns = 0;  ///< meaningful when count > 0
  std::int64_t last_ns = 0;

  void add(std::int64_t t) {
    first_ns = count == 0 ? t : std::min(first_ns, t);
    last_ns = count == 0 ? t : std::max(last_ns, t);
    ++count;
  }

  void merge(const MessageSpan& part) {
    if (part.count == 0) return;
    first_ns = count == 0 ? part.first_ns : std::min(first_ns, part.first_ns);
    last_ns = count == 0 ? part.last_ns : std::max(last_ns, part.last_ns);
    count += part.count;
  }
};

}  // namespace ulc::bags
