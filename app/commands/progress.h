// The progress line of the commands that run a campaign's runs (run, export): on stderr, a bar
// redrawn in place on a terminal, otherwise (a log, or CI set) a plain line every 20 s at most
// and the last one: "progress: 52/208 runs, 14.0 runs/s, 11 s left".
#pragma once

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace armfault {

class Progress {
 public:
  explicit Progress(bool enabled)
      : enabled_(enabled), tty_(isatty(STDERR_FILENO) != 0 && std::getenv("CI") == nullptr) {}
  void Update(long done, long total) {
    if (!enabled_ || total == 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (!started_) {
      started_ = true;
      start_ = last_ = now;
      first_done_ = done;
    }
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const long ran = done - first_done_;
    const double rate = elapsed > 0 ? ran / elapsed : 0;
    const double left = rate > 0 ? (total - done) / rate : 0;
    if (tty_) {
      // One line, redrawn in place, as wide as the terminal allows.
      char text[128];
      std::snprintf(text, sizeof text, " %ld/%ld runs  %.1f runs/s  %.0f s left", done, total, rate, left);
      winsize ws{};
      const int columns = ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 ? ws.ws_col : 80;
      const int width = std::max(0, std::min(40, columns - static_cast<int>(std::strlen(text)) - 3));
      const int filled = static_cast<int>(width * done / total);
      std::fprintf(stderr, "\r%s%s%s%s\033[K", width > 0 ? "[" : "", std::string(filled, '#').c_str(),
                   (std::string(width - filled, '.') + (width > 0 ? "]" : "")).c_str(), text);
      if (done == total) std::fprintf(stderr, "\n");
    } else {
      // Logs (no terminal, or CI set): a line every 20 s at most, and the last one.
      if (done == total || std::chrono::duration<double>(now - last_).count() >= 20.0) {
        std::fprintf(stderr, "progress: %ld/%ld runs, %.1f runs/s, %.0f s left\n", done, total, rate, left);
        last_ = now;
      }
    }
    last_done_ = done;
  }

 private:
  bool enabled_, tty_;
  bool started_ = false;
  std::chrono::steady_clock::time_point start_, last_;
  long first_done_ = 0, last_done_ = 0;
};

}  // namespace armfault
