#include "app/batch/local_engine.hpp"

#include <fmt/core.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

#include "io/interrupt.hpp"
#include "io/progress.hpp"
#include "io/results_dir.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace wingman::app {
namespace {

pid_t spawn_worker(const RunSpec& spec, std::uint64_t seed, const fs::path& out) {
  std::vector<std::string> args = {"wingman"};
  for (auto& a : run_arguments(spec, std::to_string(seed), out)) args.push_back(std::move(a));
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  const std::string log = run_log(out, seed).string();
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  // Workers ignore the terminal's Ctrl-C; the parent stops them, so none dies half-way through
  // writing unnoticed.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  pid_t pid = -1;
  // The worker learns its parent (io/interrupt.hpp: it stops when the parent dies, even by SIGKILL).
  std::vector<std::string> env_text = {std::string(io::kWorkerOfEnv) + "=" + std::to_string(::getpid())};
  for (char** e = environ; *e; ++e)
    if (std::string(*e).rfind(std::string(io::kWorkerOfEnv) + "=", 0) != 0) env_text.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  const int rc = posix_spawn(&pid, "/proc/self/exe", &fa, &attr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) throw std::runtime_error(fmt::format("cannot start a worker: {}", std::strerror(rc)));
  return pid;
}

}  // namespace

EngineEnd run_local(const RunSpec& spec, const fs::path& out, const std::vector<std::uint64_t>& pending,
                    int jobs, bool quiet, SeedOutcomes& seeds) {
  std::map<pid_t, std::uint64_t> running;
  std::size_t next = 0, done_now = 0;
  io::ProgressLine progress("[montecarlo]", quiet);
  auto status = [&] { return fmt::format("runs ({} running, {} failed)", running.size(), seeds.failed.size()); };
  while (!io::interrupt_signal() && (next < pending.size() || !running.empty())) {
    while (!io::interrupt_signal() && next < pending.size() && static_cast<int>(running.size()) < jobs) {
      const std::uint64_t seed = pending[next++];
      running[spawn_worker(spec, seed, out)] = seed;
    }
    progress.update(static_cast<int>(done_now), static_cast<int>(pending.size()), status());
    int st = 0;
    const pid_t pid = ::waitpid(-1, &st, 0);  // EINTR when a signal arrives
    if (pid < 0) {
      if (errno == EINTR) continue;
      break;
    }
    auto it = running.find(pid);
    if (it == running.end()) continue;
    const std::uint64_t seed = it->second;
    running.erase(it);
    ++done_now;
    const fs::path log = run_log(out, seed);
    if (WIFEXITED(st) && WEXITSTATUS(st) == 0) {
      seeds.finished.push_back(seed);
    } else {
      const std::string why = WIFEXITED(st) ? fmt::format("exit {}: {}", WEXITSTATUS(st), last_line(log))
                                            : fmt::format("killed by signal {}", WTERMSIG(st));
      seeds.failed.emplace_back(seed, why);
      fmt::print(stderr, "\nrun seed {} failed ({}); log: {}\n", seed, why, log.string());
    }
  }
  progress.update(static_cast<int>(done_now), static_cast<int>(pending.size()), status());
  progress.finish();
  if (!io::interrupt_signal()) return EngineEnd::done;
  for (const auto& [pid, seed] : running) ::kill(pid, SIGTERM);
  for (const auto& [pid, seed] : running) ::waitpid(pid, nullptr, 0);
  io::ResultsDir::remove_stale_staging(out / "runs");
  return EngineEnd::interrupted;
}

}  // namespace wingman::app
