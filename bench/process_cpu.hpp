// CPU seconds of the whole process, every thread included (llvmpipe's rasteriser threads too): on
// a machine shared with other work this says what an iteration costs better than wall time does.
#pragma once

#include <sys/resource.h>

namespace wingman::bench {

inline double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

}  // namespace wingman::bench
