// A one-line progress display on stderr: redrawn in place on a terminal, a line per 10 % when
// stderr is a file or a pipe (CI logs), nothing when quiet.
#pragma once

#include <chrono>
#include <string>

namespace wingman::io {

class ProgressLine {
 public:
  ProgressLine(std::string label, bool quiet);
  void update(int done, int total, const std::string& extra = "");
  void finish();

 private:
  std::string label_;
  bool quiet_, tty_;
  int last_decile_ = -1;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace wingman::io
