// Wall-clock stage timings of the pipeline (per-step prediction, update, rendering, detection...).
#pragma once

#include <chrono>

namespace wingman::io {

using Clock = std::chrono::steady_clock;
// Milliseconds elapsed since t0.
inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace wingman::io
