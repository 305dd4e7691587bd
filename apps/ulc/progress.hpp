// Progress on stderr, as docs/design.md asks: a redrawn bar on a terminal, plain lines when piped
// (one line per 10 %), nothing with --quiet. Each shows the stage, its share done (with the
// frames done of frames to do when the caller counts frames), the time it has taken and the time
// it should still take at its pace so far ("left").
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace ulc::app {

class Progress {
 public:
  Progress(std::string stage, bool quiet)
      : stage_(std::move(stage)), quiet_(quiet), terminal_(isatty(STDERR_FILENO) == 1) {}

  /// `done` of `total` items (frames) done.
  void update(std::size_t done, std::size_t total) {
    if (total == 0) return;
    show(static_cast<double>(done) / static_cast<double>(total),
         " (" + std::to_string(done) + "/" + std::to_string(total) + ")");
  }

  /// A share in [0, 1] done, of work not counted in frames.
  void update_fraction(double fraction) { show(fraction, ""); }

  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  void show(double fraction, const std::string& counts) {
    if (quiet_ || finished_) return;
    const int percent = static_cast<int>(100.0 * std::min(std::max(fraction, 0.0), 1.0));
    const bool done = percent == 100;
    if (terminal_ ? percent == last_percent_ && !done : percent / 10 == last_percent_ / 10 && !done)
      return;
    const std::string time = timing(fraction, done);
    if (terminal_) {
      constexpr int kWidth = 30;
      const int filled = kWidth * percent / 100;
      std::fprintf(stderr, "\r%-24s [%s%s] %3d%%%s %s\033[K%s", stage_.c_str(),
                   std::string(static_cast<std::size_t>(filled), '#').c_str(),
                   std::string(static_cast<std::size_t>(kWidth - filled), '.').c_str(), percent,
                   counts.c_str(), time.c_str(), done ? "\n" : "");
    } else {
      std::fprintf(stderr, "%s: %d%%%s %s\n", stage_.c_str(), percent, counts.c_str(),
                   time.c_str());
    }
    std::fflush(stderr);
    last_percent_ = percent;
    finished_ = done;
  }

  /// "12.3 s" and, before the end, ", 17.0 s left" at the pace so far.
  std::string timing(double fraction, bool done) const {
    const double t = elapsed();
    char text[64];
    if (done || !(fraction > 0.0))
      std::snprintf(text, sizeof text, "%.1f s", t);
    else
      std::snprintf(text, sizeof text, "%.1f s, %.0f s left", t, t * (1.0 - fraction) / fraction);
    return text;
  }

  std::string stage_;
  bool quiet_;
  bool terminal_;
  bool finished_ = false;    // 100 % was shown: later updates of the same stage are not
  int last_percent_ = -100;  // no decile yet: the first update always prints (-1 / 10 == 0)
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace ulc::app
