// SIGINT and SIGTERM for the long commands (run, slam, render, bench-frontend): the handler only
// sets a flag; loops call throw_if_interrupted() between steps, so the exception unwinds through
// the staging directories' destructors (nothing half-written stays) and run_cli exits 128 + signal
// (130 for Ctrl-C, 143 for SIGTERM), as a shell reports a process the signal killed.
#pragma once

#include <stdexcept>

namespace wingman::app {

struct Interrupted : std::runtime_error {
  explicit Interrupted(int signal);
  int signal;
  int exit_code() const { return 128 + signal; }
};

// Installs the handlers for its lifetime and restores the previous ones afterwards.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
};

// The signal received since the guard was installed, or 0.
int interrupt_signal();
void throw_if_interrupted();

}  // namespace wingman::app
