// Whole-file reads and writes for the I/O layer, throwing IoError with the path and the reason.
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

inline void write_file_bytes(const std::filesystem::path& path,
                             const std::vector<unsigned char>& bytes) {
  const std::string name = path.string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out)
    throw IoError(name, "", std::string("cannot open for writing: ") + std::strerror(errno));
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  out.flush();
  if (!out) throw IoError(name, "", "write failed");
}

}  // namespace ulc::io
