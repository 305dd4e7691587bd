// Progress on stderr, as docs/design.md asks: a redrawn bar on a terminal, plain lines when piped
// (one line per 10 %), nothing with --quiet.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace ulc::app {

class Progress {
 public:
  Progress(std::string stage, bool quiet)
      : stage_(std::move(stage)), quiet_(quiet), terminal_(isatty(STDERR_FILENO) == 1) {}

  void update(std::size_t done, std::size_t total) {
    if (quiet_ || total == 0) return;
    const int percent = static_cast<int>(100 * done / total);
    if (terminal_) {
      if (percent == last_percent_) return;
      constexpr int kWidth = 30;
      const int filled = kWidth * percent / 100;
      std::fprintf(stderr, "\r%-12s [%s%s] %3d%% (%zu/%zu)", stage_.c_str(),
                   std::string(static_cast<std::size_t>(filled), '#').c_str(),
                   std::string(static_cast<std::size_t>(kWidth - filled), '.').c_str(), percent,
                   done, total);
      if (done == total) std::fprintf(stderr, "  %.1f s\n", elapsed());
    } else {
      if (percent / 10 == last_percent_ / 10 && done != total) return;
      std::fprintf(stderr, "%s: %d%% (%zu/%zu) %.1f s\n", stage_.c_str(), percent, done, total,
                   elapsed());
    }
    std::fflush(stderr);
    last_percent_ = percent;
  }

  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::string stage_;
  bool quiet_;
  bool terminal_;
  int last_percent_ = -100;  // no decile yet: the first update always prints (-1 / 10 == 0)
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace ulc::app
