// Strict, locale-independent text helpers for the ascii formats and text headers.
//
// Numbers must be the whole token ("1.5x" and "" are rejected); std::from_chars never looks at
// the C locale, so a German locale cannot turn "1.5" into garbage.
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace ulc::io {

inline bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

/// Splits on spaces and tabs into `out` (cleared first); views point into `line`.
inline void split_tokens(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const std::size_t begin = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > begin) out.push_back(line.substr(begin, i - begin));
  }
}

inline std::vector<std::string_view> split_tokens(std::string_view line) {
  std::vector<std::string_view> out;
  split_tokens(line, out);
  return out;
}

inline bool is_blank_line(std::string_view line) {
  for (char c : line)
    if (!is_blank(c)) return false;
  return true;
}

/// Whole-token unsigned decimal integer.
inline bool parse_uint(std::string_view token, std::uint64_t& value) {
  if (token.empty()) return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

/// Whole-token floating-point number; accepts a leading '+', "nan" and "inf".
inline bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty() || token.front() == '+') return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

/// Whole-token float (parsed as float, not rounded twice through double); accepts '+', nan, inf.
inline bool parse_float(std::string_view token, float& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty() || token.front() == '+') return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

/// Quoted token for error messages, cut short so a binary blob cannot flood a message.
inline std::string quote_token(std::string_view token) {
  constexpr std::size_t kMax = 40;
  std::string s = "'";
  for (std::size_t i = 0; i < token.size() && i < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    s += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
  }
  if (token.size() > kMax) s += "...";
  return s + "'";
}

}  // namespace ulc::io
