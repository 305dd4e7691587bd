#include "frame_spool.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "ulc/io/io_error.hpp"

namespace ulc::app {
namespace {

[[noreturn]] void spool_failed(const std::string& what) {
  throw io::IoError(what, "",
                    std::string("cannot spool a frame to a temporary file: ") +
                        std::strerror(errno) + " (set TMPDIR to a larger disk)");
}

template <class T>
void write_all(std::FILE* f, const std::vector<T>& v, const std::string& what) {
  if (!v.empty() && std::fwrite(v.data(), sizeof(T), v.size(), f) != v.size()) spool_failed(what);
}

/// Reads v.size() items at `offset`; false when the file is short.
template <class T>
bool read_at(int fd, long& offset, std::vector<T>& v) {
  auto* bytes = reinterpret_cast<char*>(v.data());
  std::size_t left = v.size() * sizeof(T);
  while (left > 0) {
    const ssize_t got = ::pread(fd, bytes, left, offset);
    if (got <= 0) return false;
    bytes += got;
    left -= static_cast<std::size_t>(got);
    offset += got;
  }
  return true;
}

}  // namespace

SpooledFrames::SpooledFrames(std::string what)
    : what_(std::move(what)), file_(std::tmpfile(), &std::fclose) {
  if (!file_)
    throw io::IoError(what_, "",
                      std::string("cannot make a temporary file to hold its frames: ") +
                          std::strerror(errno) + " (set TMPDIR)");
}

void SpooledFrames::append(const PointCloud<float>& cloud) {
  Entry e{end_, cloud.points.size(), cloud.has_times(), cloud.has_intensities()};
  write_all(file_.get(), cloud.points, what_);
  if (e.times) write_all(file_.get(), cloud.times, what_);
  if (e.intensities) write_all(file_.get(), cloud.intensities, what_);
  if (std::fflush(file_.get()) != 0) spool_failed(what_);
  end_ = std::ftell(file_.get());
  frames_.push_back(e);
}

PointCloud<float> SpooledFrames::load(std::size_t i) const {
  const Entry& e = frames_[i];
  PointCloud<float> cloud;
  cloud.points.resize(e.points);
  if (e.times) cloud.times.resize(e.points);
  if (e.intensities) cloud.intensities.resize(e.points);
  const int fd = ::fileno(file_.get());
  long offset = e.offset;
  if (read_at(fd, offset, cloud.points) && read_at(fd, offset, cloud.times) &&
      read_at(fd, offset, cloud.intensities))
    return cloud;
  fail(what_ + ": frame " + std::to_string(i) + " could not be read back from its temporary file");
  return {};
}

}  // namespace ulc::app
