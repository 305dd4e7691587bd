// ulc::io::IoError: the one exception type of the I/O layer.
//
// Every reader and writer under include/ulc/io reports a problem by throwing IoError (and only
// IoError) with the file, a position inside it and a reason, so a caller can print one clear
// line: what() reads "<file>: <position>: <reason>", or "<file>: <reason>" when the position is
// unknown or meaningless (a missing file, a folder without frames).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

namespace ulc::io {

class IoError : public std::runtime_error {
 public:
  IoError(std::string file, std::string position, std::string reason)
      : std::runtime_error(compose(file, position, reason)),
        file_(std::move(file)),
        position_(std::move(position)),
        reason_(std::move(reason)) {}

  const std::string& file() const noexcept { return file_; }
  /// Human position such as "byte 1234" or "line 12"; empty when not applicable.
  const std::string& position() const noexcept { return position_; }
  const std::string& reason() const noexcept { return reason_; }

 private:
  static std::string compose(const std::string& file, const std::string& position,
                             const std::string& reason) {
    return position.empty() ? file + ": " + reason : file + ": " + position + ": " + reason;
  }

  std::string file_;
  std::string position_;
  std::string reason_;
};

/// Position strings, spelled the same way everywhere.
inline std::string at_byte(std::size_t offset) {
  return "byte " + std::to_string(offset);
}
inline std::string at_line(std::size_t line) {
  return "line " + std::to_string(line);
}

}  // namespace ulc::io
