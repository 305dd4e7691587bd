// Shortest round-trip decimal text for the ascii writers (std::to_chars: exact and
// locale-independent, so reading the text back gives the same float / double bits).
#pragma once

#include <charconv>
#include <string>

namespace ulc::io {

template <typename T>
void append_number(std::string& out, T value) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof(buf), value);
  out.append(buf, res.ptr);
}

}  // namespace ulc::io
