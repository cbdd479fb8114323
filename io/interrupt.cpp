#include "io/interrupt.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <string>

namespace wingman::io {
namespace {

std::atomic<int> g_signal{0};
extern "C" void on_interrupt(int sig) { g_signal = sig; }

struct sigaction g_old_int {}, g_old_term {}, g_old_pipe {};

const char* signal_name(int sig) {
  return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : sig == SIGPIPE ? "SIGPIPE" : "a signal";
}

}  // namespace

Interrupted::Interrupted(int sig)
    : std::runtime_error(std::string("interrupted by ") + signal_name(sig) +
                         ": stopped, nothing written (the staged output is removed)"),
      signal(sig) {}

InterruptGuard::InterruptGuard() {
  g_signal = 0;
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &g_old_int);
  sigaction(SIGTERM, &sa, &g_old_term);
  sigaction(SIGPIPE, &sa, &g_old_pipe);  // `wingman run ... | head`: stop cleanly, not die half-way
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &g_old_int, nullptr);
  sigaction(SIGTERM, &g_old_term, nullptr);
  sigaction(SIGPIPE, &g_old_pipe, nullptr);
}

void stop_with_parent() {
  const char* parent = std::getenv(kWorkerOfEnv);
  if (!parent) return;
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (std::to_string(::getppid()) != parent) g_signal = SIGTERM;  // died before prctl took hold
}

int interrupt_signal() { return g_signal; }

void throw_if_interrupted() {
  if (const int sig = g_signal) throw Interrupted(sig);
}

}  // namespace wingman::io
