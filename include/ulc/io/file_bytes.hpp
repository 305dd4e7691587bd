// Whole-file reads and writes for the I/O layer, throwing IoError with the path and the reason.
// Writes are atomic (atomic_file.hpp).
//
// Readers load a file into memory once and parse it with ByteReader: the file size is then the
// bound every later allocation is checked against.
#pragma once

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "ulc/io/atomic_file.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::io {

inline std::vector<unsigned char> read_file_bytes(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw IoError(name, "", "no such file");
  if (std::filesystem::is_directory(status))
    throw IoError(name, "", "is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(name, "", std::string("cannot open for reading: ") + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const std::streamoff end = in.tellg();
  if (end < 0) throw IoError(name, "", "cannot determine the file size");
  in.seekg(0, std::ios::beg);
  std::vector<unsigned char> bytes(static_cast<std::size_t>(end));
  if (!bytes.empty() &&
      !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size())))
    throw IoError(name, "", "read failed");
  return bytes;
}

/// Writes `bytes` to `path` atomically (atomic_file.hpp): never a half-written file.
inline void write_file_bytes(const std::filesystem::path& path,
                             const std::vector<unsigned char>& bytes) {
  write_file_atomically(path, bytes.data(), bytes.size());
}

/// Writes `text` to `path` atomically, as write_file_bytes.
inline void write_file_text(const std::filesystem::path& path, const std::string& text) {
  write_file_atomically(path, text.data(), text.size());
}

}  // namespace ulc::io
