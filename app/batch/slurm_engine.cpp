#include "app/batch/slurm_engine.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "io/interrupt.hpp"
#include "io/progress.hpp"
#include "app/batch/slurm_queue.hpp"
#include "io/usage_error.hpp"
#include "app/batch/subprocess.hpp"
#include "io/atomic_file.hpp"
#include "io/results_dir.hpp"

namespace fs = std::filesystem;

namespace wingman::app {
namespace {

using Clock = std::chrono::steady_clock;

// A task gone from the queue without a status file is failed only after this long: a file
// written on a node can reach this machine's view of a network filesystem a few seconds late.
constexpr auto kLostAfter = std::chrono::seconds(15);

struct Task {
  Task(std::string job, int index, std::uint64_t seed) : job(std::move(job)), index(index), seed(seed) {}
  std::string job;
  int index = 0;  // in the array
  std::uint64_t seed = 0;
  bool ended = false, lost = false;
  std::optional<Clock::time_point> missing_since;  // gone from the queue, no status file yet
};

// The tasks of recorded jobs still queued or running a seed of `pending`.
std::vector<Task> live_recorded_tasks(const fs::path& out, const std::vector<std::uint64_t>& pending) {
  std::set<std::uint64_t> wanted(pending.begin(), pending.end());
  std::vector<Task> tasks;
  for (const RecordedJob& job : read_jobs(out)) {
    std::string error;
    const auto live = live_tasks(job.id, error);
    if (!live)
      throw std::runtime_error(fmt::format("cannot ask Slurm about job {} of {} (squeue: {}); try again once "
                                           "the controller answers", job.id, out.string(), error));
    for (const auto& [index, state] : *live) {
      if (index < 0 || static_cast<std::size_t>(index) >= job.seeds.size()) continue;
      if (wanted.erase(job.seeds[static_cast<std::size_t>(index)]))
        tasks.emplace_back(job.id, index, job.seeds[static_cast<std::size_t>(index)]);
    }
  }
  return tasks;
}

std::string seed_range(const std::vector<std::uint64_t>& seeds) {
  if (seeds.size() == 1) return fmt::format("seed {}", seeds.front());
  const bool contiguous = seeds.back() - seeds.front() + 1 == seeds.size();
  return contiguous ? fmt::format("seeds {}..{}", seeds.front(), seeds.back()) : fmt::format("seeds {}", fmt::join(seeds, ","));
}

// Writes submission k's seeds and script, submits it and records the job; a refused submission
// leaves neither file behind. `after`: a job the tasks wait for (its id), or "".
std::vector<Task> submit(const SlurmStudy& s, const SlurmOptions& o, const std::vector<std::uint64_t>& seeds,
                         const std::string& after = "") {
  fs::create_directories(slurm_dir(s.out) / "logs");
  fs::create_directories(slurm_dir(s.out) / "status");
  int k = 1;
  while (fs::exists(script_path(s.out, k)) || fs::exists(seeds_path(s.out, k))) ++k;
  const ArrayJob job{s.out, k, seeds, "wingman-" + s.name, fs::read_symlink("/proc/self/exe"), fs::current_path(), after};
  std::string list;
  for (auto seed : seeds) list += std::to_string(seed) + "\n";
  io::write_file_atomic(seeds_path(s.out, k), list);
  io::write_file_atomic(script_path(s.out, k), array_script(job, s.spec, o));
  std::string id;
  try {
    id = submit_array(script_path(s.out, k));
  } catch (...) {
    std::error_code ec;
    fs::remove(script_path(s.out, k), ec);
    fs::remove(seeds_path(s.out, k), ec);
    throw;
  }
  record_job(s.out, id, k);
  if (!s.quiet)
    fmt::print(stderr, "submitted Slurm job {}: {} runs ({}), script {}\n", id, seeds.size(), seed_range(seeds),
               script_path(s.out, k).string());
  std::vector<Task> tasks;
  for (std::size_t i = 0; i < seeds.size(); ++i) tasks.emplace_back(id, static_cast<int>(i), seeds[i]);
  return tasks;
}

// An argument as a shell user would type it: quoted only when it needs to be.
std::string typed(const std::string& arg) {
  const bool plain = !arg.empty() && std::all_of(arg.begin(), arg.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("_./=:,+@%-").find(c) != std::string_view::npos;
  });
  return plain ? arg : shell_quote(arg);
}

// This very command line without --detach and with --resume: what follows the job later.
std::string resume_command() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::vector<std::string> args;
  for (std::string a; std::getline(in, a, '\0');) args.push_back(a);
  std::erase(args, std::string("--detach"));
  if (std::find(args.begin(), args.end(), "--resume") == args.end()) args.emplace_back("--resume");
  std::string cmd;
  for (const auto& a : args) {
    if (!cmd.empty()) cmd += ' ';  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on " " + s
    cmd += typed(a);
  }
  return cmd;
}

// The jobs with tasks not ended yet: "12", or "12 15" (as scancel takes them).
std::string job_ids(const std::vector<Task>& tasks) {
  std::vector<std::string> ids;
  for (const Task& t : tasks)
    if (!t.ended && std::find(ids.begin(), ids.end(), t.job) == ids.end()) ids.push_back(t.job);
  return fmt::format("{}", fmt::join(ids, " "));
}

// "job 12" or "jobs 12 15".
std::string jobs_named(const std::vector<Task>& tasks) {
  const std::string ids = job_ids(tasks);
  return (ids.find(' ') == std::string::npos ? "job " : "jobs ") + ids;
}

void end_task(const fs::path& out, Task& t, int exit_code, SeedOutcomes& seeds) {
  t.ended = true;
  if (exit_code == 0 && io::ResultsDir::is_results_dir(run_dir(out, t.seed))) {
    seeds.finished.push_back(t.seed);
    return;
  }
  const fs::path log = run_log(out, t.seed);
  const std::string why = exit_code == 0 ? fmt::format("exit 0 but no results directory {}", run_dir(out, t.seed).string())
                                         : fmt::format("exit {}: {}", exit_code, last_line(log));
  seeds.failed.emplace_back(t.seed, why);
  fmt::print(stderr, "\nrun seed {} failed ({}); log: {}\n", t.seed, why, log.string());
}

// Gone from the queue with no exit status: Slurm ended it (scancel, past --time, a node failure),
// or it could not write into the output directory; Slurm's own log of the task says which.
void lose_task(const fs::path& out, Task& t, SeedOutcomes& seeds) {
  t.ended = t.lost = true;
  const fs::path log = task_log(out, t.job, t.index);
  const bool logged = fs::exists(log);
  const std::string why = fmt::format(
      "Slurm task {}_{} ended without recording an exit status (cancelled, past --time, or its node "
      "failed?): {}", t.job, t.index, logged ? last_line(log) : "no Slurm log in " + log.parent_path().string());
  seeds.failed.emplace_back(t.seed, why);
  fmt::print(stderr, "\nrun seed {} failed ({}){}\n", t.seed, why, logged ? "; Slurm's log: " + log.string() : "");
}

struct Counts {
  int ended = 0, running = 0, pending = 0;
};

// One look at the queue, then at the status files (in that order: a task missing from the queue
// wrote its status, if it ever does, before it left), ending the tasks that have ended.
Counts poll(const fs::path& out, std::vector<Task>& tasks, SeedOutcomes& seeds, bool& warned) {
  std::map<std::string, std::optional<std::map<int, std::string>>> queue;
  for (const Task& t : tasks) {
    if (t.ended || queue.count(t.job)) continue;
    std::string error;
    queue[t.job] = live_tasks(t.job, error);
    if (!queue[t.job] && !warned) fmt::print(stderr, "\nwarning: squeue failed ({}); still waiting\n", error);
    warned = warned || !queue[t.job];
  }
  const auto statuses = read_statuses(out);
  Counts c;
  for (Task& t : tasks) {
    const auto st = statuses.find(t.seed);
    if (!t.ended && st != statuses.end() && st->second.task == fmt::format("{}_{}", t.job, t.index))
      end_task(out, t, st->second.exit_code, seeds);
    if (t.ended) {
      ++c.ended;
      continue;
    }
    const auto& live = queue[t.job];
    if (live && live->count(t.index)) {
      t.missing_since.reset();
      ++(live->at(t.index) == "PD" ? c.pending : c.running);
      continue;
    }
    if (live && !t.missing_since) t.missing_since = Clock::now();
    if (live && Clock::now() - *t.missing_since >= kLostAfter) {
      lose_task(out, t, seeds);
      ++c.ended;
    } else {
      ++c.running;  // ending, or unknown while squeue fails
    }
  }
  return c;
}

// Sleeps until the next poll: every second at first, every 10 s after a couple of minutes (squeue
// is a request to a controller shared by everyone). False on SIGINT/SIGTERM.
bool wait_for_next_poll(Clock::duration elapsed) {
  const auto interval = std::clamp<Clock::duration>(elapsed / 10, std::chrono::seconds(1), std::chrono::seconds(10));
  const auto until = Clock::now() + interval;
  while (!io::interrupt_signal() && Clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  return !io::interrupt_signal();
}

// Every task of a job ended without a status file or a Slurm log here: the nodes most likely
// wrote them into their own copy of the directory.
void note_unshared(const fs::path& out, const std::vector<Task>& tasks) {
  std::map<std::string, bool> all_lost;
  for (const Task& t : tasks) {
    auto [it, first] = all_lost.try_emplace(t.job, true);
    it->second = it->second && t.lost && !fs::exists(task_log(out, t.job, t.index));
  }
  for (const auto& [job, lost] : all_lost)
    if (lost)
      fmt::print(stderr, "note: no task of Slurm job {} wrote its exit status or its log into {}: unless the job "
                 "was cancelled before any task ran, {} is probably not on a filesystem the compute nodes share "
                 "with this machine\n", job, out.string(), out.string());
}

EngineEnd follow(const SlurmStudy& s, std::vector<Task>& tasks, SeedOutcomes& seeds) {
  io::ProgressLine progress("[montecarlo]", s.quiet);
  const auto start = Clock::now();
  const std::size_t failed_before = seeds.failed.size();
  bool warned = false;
  const int total = static_cast<int>(tasks.size());
  for (;;) {
    const Counts c = poll(s.out, tasks, seeds, warned);
    progress.update(c.ended, total, fmt::format("runs ({} running, {} pending, {} failed)", c.running, c.pending,
                                                seeds.failed.size() - failed_before));
    if (c.ended == total) break;
    if (!wait_for_next_poll(Clock::now() - start)) {
      progress.finish();
      fmt::print(stderr, "interrupted: stopped following; {} of {} runs not ended yet stay on the cluster "
                 "(Slurm {}).\n  cancel them:           scancel {}\n  follow and aggregate:  {}\n",
                 total - c.ended, total, jobs_named(tasks), job_ids(tasks), resume_command());
      return EngineEnd::interrupted;
    }
  }
  progress.finish();
  note_unshared(s.out, tasks);
  return EngineEnd::done;
}

}  // namespace

void check_slurm_clients() {
  for (const char* client : {"sbatch", "squeue"})
    if (find_on_path(client).empty())
      throw io::UsageError(fmt::format("--engine slurm: {} was not found on PATH; install Slurm's client commands "
                                   "(Debian: slurm-client) or use --engine local", client));
}

void check_recorded_jobs(const fs::path& out, bool resume, bool slurm_engine) {
  const auto jobs = read_jobs(out);
  if (jobs.empty()) return;
  std::vector<std::string> ids;
  for (const auto& j : jobs) ids.push_back(j.id);
  if (!resume)
    throw io::UsageError(fmt::format("{}: holds the runs of Slurm job {} ({}); pass --resume to follow and "
                                 "aggregate them, or choose another --out", out.string(), fmt::join(ids, ", "),
                                 (slurm_dir(out) / "jobs").string()));
  if (slurm_engine || find_on_path("squeue").empty()) return;
  for (const auto& j : jobs) {
    std::string error;
    const auto live = live_tasks(j.id, error);
    if (live && !live->empty())
      throw io::UsageError(fmt::format("{}: Slurm job {} still has {} runs queued or running; follow it with "
                                   "--engine slurm --resume, or cancel it (scancel {}) first",
                                   out.string(), j.id, live->size(), j.id));
  }
}

EngineEnd run_slurm(const SlurmStudy& s, const SlurmOptions& o, const std::vector<std::uint64_t>& pending,
                    SeedOutcomes& seeds) {
  std::vector<Task> tasks = live_recorded_tasks(s.out, pending);
  if (tasks.empty())  // no task of ours runs anywhere: staging directories left are stale
    for (const auto& note : io::ResultsDir::remove_stale_staging(s.out / "runs"))
      if (!s.quiet) fmt::print(stderr, "note: {}\n", note);
  if (!tasks.empty() && !s.quiet)
    fmt::print(stderr, "following Slurm {}: {} runs still queued or running\n", jobs_named(tasks), tasks.size());
  std::vector<std::uint64_t> rest;
  for (auto seed : pending)
    if (std::none_of(tasks.begin(), tasks.end(), [&](const Task& t) { return t.seed == seed; })) rest.push_back(seed);
  if (rest.size() > 1 && s.fill_cache_first) {
    // An empty frame cache: the first seed's task renders every frame once, and the others start
    // when it has ended and read them, instead of each rendering them side by side.
    auto first = submit(s, o, {rest.front()});
    auto added = submit(s, o, {rest.begin() + 1, rest.end()}, first.front().job);
    tasks.insert(tasks.end(), first.begin(), first.end());
    tasks.insert(tasks.end(), added.begin(), added.end());
  } else if (!rest.empty()) {
    auto added = submit(s, o, rest);
    tasks.insert(tasks.end(), added.begin(), added.end());
  }
  if (o.detach && !tasks.empty()) {
    fmt::print("Slurm {} runs {} of the {} seeds; this command does not wait for it.\n"
               "follow it and aggregate: {}\ncancel it: scancel {}\n",
               jobs_named(tasks), tasks.size(), tasks.size() + seeds.finished.size(), resume_command(), job_ids(tasks));
    return EngineEnd::detached;
  }
  return tasks.empty() ? EngineEnd::done : follow(s, tasks, seeds);
}

}  // namespace wingman::app
