// SIGINT, SIGTERM (and SIGPIPE, a closed output pipe) for the long commands: the handler only
// sets a flag; loops call throw_if_interrupted() between steps, so the exception unwinds through
// the staging directories' destructors (nothing half-written stays) and run_cli exits 128 + signal
// (130 for Ctrl-C, 143 for SIGTERM), as a shell reports a process the signal killed.
#pragma once

#include <stdexcept>

namespace wingman::io {

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

// A Monte Carlo worker's environment names its parent's pid here; the worker asks the kernel for
// SIGTERM when that parent dies, so a killed `wingman montecarlo` leaves no orphan runs behind.
inline constexpr const char* kWorkerOfEnv = "WINGMAN_WORKER_OF";
// Called once at start: with kWorkerOfEnv set, SIGTERM on the parent's death (and at once if the
// parent is already gone).
void stop_with_parent();

// The signal received since the guard was installed, or 0.
int interrupt_signal();
void throw_if_interrupted();

}  // namespace wingman::io
