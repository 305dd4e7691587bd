// Atomic output: a file is written as a temporary in its own folder, then renamed over its name.
// rename(2) within one folder is atomic on POSIX, so a reader - or a run stopped half-way - sees
// the old file, no file, or the whole new one, never a half-written one. The temporary is
// ".<name>.ulc-tmp-<pid>-<n>" beside the target and is removed on any error.
//
// The temporaries being written are listed in a fixed table that a signal handler may read:
// remove_pending_temporaries() is async-signal-safe (lock-free atomic loads and unlink(2) only),
// so a process stopped by Ctrl-C removes them before it exits (apps/ulc/interrupt.cpp). The
// guarantee is against the process being stopped, not against power loss (no fsync).
#pragma once

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "ulc/io/io_error.hpp"

namespace ulc::io {

/// Part of every temporary file name (tests look for leftovers by it).
inline constexpr const char* kTemporaryMarker = ".ulc-tmp-";

namespace atomic_detail {

/// Concurrent writers beyond this wait for a free slot (`ulc simulate` writes a frame per thread).
constexpr std::size_t kSlots = 64;
constexpr std::size_t kPathBytes = 4096;  // PATH_MAX on Linux

enum SlotState : int { kFree = 0, kClaimed = 1, kPending = 2 };

struct Slot {
  std::atomic<int> state{kFree};
  char path[kPathBytes] = {};
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads the slots");

inline Slot g_slots[kSlots];
inline std::atomic<unsigned long> g_counter{0};

/// Claims a free slot and records `path` in it; kPending once the path is complete.
inline Slot& register_temporary(const std::string& path) {
  for (;;) {
    for (Slot& s : g_slots) {
      int expected = kFree;
      if (!s.state.compare_exchange_strong(expected, kClaimed)) continue;
      std::memcpy(s.path, path.c_str(), path.size() + 1);
      s.state.store(kPending);
      return s;
    }
    std::this_thread::yield();
  }
}

inline void release(Slot& s) {
  s.state.store(kClaimed);  // the handler no longer reads it
  s.state.store(kFree);
}

}  // namespace atomic_detail

/// Unlinks every temporary being written. Async-signal-safe: call it from a signal handler.
inline void remove_pending_temporaries() noexcept {
  for (atomic_detail::Slot& s : atomic_detail::g_slots)
    if (s.state.load() == atomic_detail::kPending) ::unlink(s.path);
}

/// A file written through a temporary beside it: write to temporary(), then commit(). Destroyed
/// without commit (an exception, an early return), it removes the temporary.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
    const std::filesystem::path name = target_.filename();
    if (name.empty()) throw IoError(target_.string(), "", "is a folder name, expected a file");
    const unsigned long n = atomic_detail::g_counter.fetch_add(1);
    temporary_ = target_.parent_path() / ("." + name.string() + kTemporaryMarker +
                                          std::to_string(::getpid()) + "-" + std::to_string(n));
    const std::string tmp = temporary_.string();
    if (tmp.size() >= atomic_detail::kPathBytes)
      throw IoError(target_.string(), "", "path too long");
    slot_ = &atomic_detail::register_temporary(tmp);
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile() {
    if (!slot_) return;
    std::error_code ec;
    std::filesystem::remove(temporary_, ec);
    atomic_detail::release(*slot_);
  }

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temporary() const { return temporary_; }

  /// Renames the temporary over the target. Throws IoError (the temporary is then removed).
  void commit() {
    if (std::rename(temporary_.c_str(), target_.c_str()) != 0)
      throw IoError(target_.string(), "", std::string("cannot replace: ") + std::strerror(errno));
    atomic_detail::release(*slot_);
    slot_ = nullptr;
  }

 private:
  std::filesystem::path target_, temporary_;
  atomic_detail::Slot* slot_ = nullptr;
};

/// Writes `size` bytes to `path` atomically (see the top). Throws IoError naming `path`.
inline void write_file_atomically(const std::filesystem::path& path, const void* data,
                                  std::size_t size) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary(), std::ios::binary | std::ios::trunc);
    if (!out)
      throw IoError(path.string(), "",
                    std::string("cannot open for writing: ") + std::strerror(errno));
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.flush();
    if (!out) throw IoError(path.string(), "", "write failed");
  }
  file.commit();
}

}  // namespace ulc::io
