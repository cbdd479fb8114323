#include "io/progress.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <cstdio>

namespace wingman::io {

ProgressLine::ProgressLine(std::string label, bool quiet)
    : label_(std::move(label)),
      quiet_(quiet),
      tty_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

void ProgressLine::update(int done, int total, const std::string& extra) {
  if (quiet_ || total <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double frac = static_cast<double>(done) / total;
  const int decile = static_cast<int>(frac * 10);
  if (tty_) {
    if (done < total && now - last_draw_ < std::chrono::milliseconds(100)) return;
  } else if (decile == last_decile_) {
    return;
  }
  last_draw_ = now;
  last_decile_ = decile;
  const double left = frac > 0 ? elapsed * (1 - frac) / frac : 0;
  const std::string line = fmt::format("{} {:3.0f}% {}/{} {} elapsed {:.1f} s, left {:.1f} s",
                                       label_, 100 * frac, done, total, extra, elapsed, left);
  if (tty_) {
    fmt::print(stderr, "\r\033[K{}", line);
    drawn_ = true;
  } else {
    fmt::print(stderr, "{}\n", line);
  }
  std::fflush(stderr);
}

void ProgressLine::finish() {
  if (!quiet_ && tty_ && drawn_) fmt::print(stderr, "\r\033[K");
  drawn_ = false;
}

}  // namespace wingman::io
