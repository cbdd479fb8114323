// `wingman montecarlo`: N seeds of a scenario in parallel worker processes (each a `wingman run`
// writing its own results directory under <out>/runs/), then the aggregate of docs/design.md, evaluation:
// average NEES with its chi^2 bounds per step, the fraction of steps inside them per phase, and
// the spread of Table 4 (eval/montecarlo), and every later variant compared with the first seed by
// seed (eval/paired: the paper scenes' single-UAV against multi-UAV). Workers are processes, not
// threads, so a crash or an abort in one run costs that run only. Ctrl-C or SIGTERM stops the
// workers and keeps the finished runs (exit 130/143); --resume skips them. A worker stops when
// its parent dies, even by SIGKILL (app/interrupt.hpp).
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <thread>

#include "app/interrupt.hpp"
#include "app/montecarlo_study.hpp"
#include "app/progress.hpp"
#include "app/subcommand.hpp"
#include "app/cli_options.hpp"
#include "app/variants.hpp"
#include "eval/atomic_file.hpp"
#include "eval/montecarlo.hpp"
#include "eval/paired.hpp"
#include "eval/plots.hpp"
#include "eval/results_dir.hpp"
#include "sim/scenario.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace wingman::app {
namespace {

constexpr const char* kMarker = ".wingman-montecarlo";

struct MonteCarloOptions {
  std::string scenario;
  int runs = 0;
  int jobs = 0;
  std::string out;
  std::uint64_t first_seed = 1;
  std::vector<std::string> variants;
  StepLimit limit;
  bool resume = false;
  int batch = 0;
  bool no_plots = false;
  bool quiet = false;
};


fs::path run_dir(const fs::path& out, std::uint64_t seed) {
  return out / "runs" / fmt::format("seed{}", seed);
}

// The last non-empty line a failed worker wrote: its error message.
std::string last_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last.empty() ? "(no output)" : last;
}

pid_t spawn_worker(const MonteCarloOptions& o, std::uint64_t seed, const fs::path& out) {
  std::vector<std::string> args = {"wingman",  "run",   o.scenario, "--seed", std::to_string(seed),
                                   "--out",    run_dir(out, seed).string(), "--no-plots", "-q"};
  for (const auto& v : o.variants) args.insert(args.end(), {"--variant", v});
  if (o.limit.duration) args.insert(args.end(), {"--duration", fmt::format("{}", *o.limit.duration)});
  if (o.limit.frames) args.insert(args.end(), {"--frames", std::to_string(*o.limit.frames)});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  const std::string log = (out / "runs" / fmt::format("seed{}.log", seed)).string();
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
  // The worker learns its parent (app/interrupt.hpp: it stops when the parent dies, even by SIGKILL).
  std::vector<std::string> env_text = {std::string(kWorkerOfEnv) + "=" + std::to_string(::getpid())};
  for (char** e = environ; *e; ++e)
    if (std::string(*e).rfind(std::string(kWorkerOfEnv) + "=", 0) != 0) env_text.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  const int rc = posix_spawn(&pid, "/proc/self/exe", &fa, &attr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) throw std::runtime_error(fmt::format("cannot start a worker: {}", std::strerror(rc)));
  return pid;
}

// Variant directories of one run: <run>/<variant> when the scenario has variants.
std::vector<std::pair<std::string, std::string>> variant_labels(const std::vector<RunConfig>& scns) {
  std::vector<std::pair<std::string, std::string>> v;  // label, subdirectory ("" = the run itself)
  const bool nested = scns.size() > 1 || !scns.front().variant.empty();
  for (const auto& s : scns) v.emplace_back(nested ? s.variant : s.name, nested ? s.variant : "");
  return v;
}

// Runs the pending seeds in `jobs` worker processes, adding each to `finished` or `failed` as it
// ends. On SIGINT/SIGTERM (app/interrupt.hpp) stops the running workers, which remove their own
// staging directories, and returns false.
bool run_workers(const MonteCarloOptions& o, const fs::path& out, const std::vector<std::uint64_t>& pending,
                 int jobs, std::vector<std::uint64_t>& finished,
                 std::vector<std::pair<std::uint64_t, std::string>>& failed) {
  std::map<pid_t, std::uint64_t> running;
  std::size_t next = 0, done_now = 0;
  ProgressLine progress("[montecarlo]", o.quiet);
  auto status = [&] { return fmt::format("runs ({} running, {} failed)", running.size(), failed.size()); };
  while (!interrupt_signal() && (next < pending.size() || !running.empty())) {
    while (!interrupt_signal() && next < pending.size() && static_cast<int>(running.size()) < jobs) {
      const std::uint64_t seed = pending[next++];
      running[spawn_worker(o, seed, out)] = seed;
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
    const fs::path log = out / "runs" / fmt::format("seed{}.log", seed);
    if (WIFEXITED(st) && WEXITSTATUS(st) == 0) {
      finished.push_back(seed);
    } else {
      const std::string why = WIFEXITED(st) ? fmt::format("exit {}: {}", WEXITSTATUS(st), last_line(log))
                                            : fmt::format("killed by signal {}", WTERMSIG(st));
      failed.emplace_back(seed, why);
      fmt::print(stderr, "\nrun seed {} failed ({}); log: {}\n", seed, why, log.string());
    }
  }
  progress.update(static_cast<int>(done_now), static_cast<int>(pending.size()), status());
  progress.finish();
  if (!interrupt_signal()) return true;
  for (const auto& [pid, seed] : running) ::kill(pid, SIGTERM);
  for (const auto& [pid, seed] : running) ::waitpid(pid, nullptr, 0);
  eval::ResultsDir::remove_stale_staging(out / "runs");
  return false;
}

// The output directory: new, or one of ours (refused without --resume if it holds runs, and
// with other settings than its runs were made with). Splits the seeds into pending and finished.
void open_study(const MonteCarloOptions& o, const fs::path& out, const std::vector<RunConfig>& scenarios,
                std::vector<std::uint64_t>& pending, std::vector<std::uint64_t>& finished) {
  std::error_code ec;
  if (fs::exists(out)) {
    if (!fs::is_directory(out) || (!fs::exists(out / kMarker) && !fs::is_empty(out, ec)))
      throw UsageError(fmt::format("{}: exists and is not a wingman Monte Carlo directory; choose "
                                   "another --out", out.string()));
  }
  for (int i = 0; i < o.runs; ++i) {
    const std::uint64_t seed = o.first_seed + static_cast<std::uint64_t>(i);
    if (eval::ResultsDir::is_results_dir(run_dir(out, seed))) {
      if (!o.resume)
        throw UsageError(fmt::format("{}: already holds finished runs (seed {}); pass --resume to "
                                     "keep them and run the rest, or choose another --out",
                                     out.string(), seed));
      finished.push_back(seed);
    } else {
      pending.push_back(seed);
    }
  }
  const std::string settings = study_settings(scenarios, o.limit);
  record_or_check_study(out, settings);  // refuses before anything is created or changed
  fs::create_directories(out / "runs");
  eval::write_file_atomic(out / kMarker, o.scenario + "\n");
  // Staging directories of workers that were stopped: never complete; dropped once their process is gone.
  for (const auto& note : eval::ResultsDir::remove_stale_staging(out / "runs"))
    if (!o.quiet) fmt::print(stderr, "note: {}\n", note);

}

int montecarlo_command(const MonteCarloOptions& o) {
  if (o.runs < 1) throw UsageError("--runs must be at least 1");
  if (o.batch != 0 && (o.batch < 2 || o.batch > o.runs))
    throw UsageError(fmt::format("--batch {}: a batch needs 2 to --runs ({}) runs", o.batch, o.runs));
  // Bad input fails here, before any work.
  const auto scenarios = select_variants(load_run_configs(o.scenario), o.variants, o.scenario);
  o.limit.seconds(scenarios.front().rate);  // a bad --duration or --frames fails here, not per worker
  if (!o.no_plots && !eval::gnuplot_available())
    throw UsageError("gnuplot with the pngcairo terminal was not found; install it (setup.sh does) "
                     "or pass --no-plots");
  const fs::path out =
      o.out.empty() ? fs::path("results") / (scenarios.front().name + "_montecarlo") : fs::path(o.out);
  const int jobs = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());

  std::vector<std::uint64_t> pending, finished;
  open_study(o, out, scenarios, pending, finished);
  if (!o.quiet && !finished.empty())
    fmt::print(stderr, "resuming: {} of {} runs already finished\n", finished.size(), o.runs);

  std::vector<std::pair<std::uint64_t, std::string>> failed;
  if (!run_workers(o, out, pending, jobs, finished, failed)) {
    const int sig = interrupt_signal();
    fmt::print(stderr, "interrupted: {} of {} runs finished and kept in {}; rerun with --resume to "
               "run the rest\n", finished.size(), o.runs, out.string());
    return 128 + sig;
  }

  // A run whose filter broke down and recorded it (estimator.on_numerical_failure: record) ends
  // early: it is a failed seed, not one to aggregate.
  std::erase_if(finished, [&](std::uint64_t seed) {
    for (const auto& [label, sub] : variant_labels(scenarios)) {
      const std::string why = eval::recorded_numerical_failure(sub.empty() ? run_dir(out, seed) : run_dir(out, seed) / sub);
      if (why.empty()) continue;
      failed.emplace_back(seed, why);
      fmt::print(stderr, "run seed {} failed ({})\n", seed, why);
      return true;
    }
    return false;
  });
  std::sort(finished.begin(), finished.end());
  if (finished.empty()) {
    fmt::print(stderr, "error: every run failed; see the logs in {}\n", (out / "runs").string());
    return 1;
  }
  std::vector<eval::MonteCarloSummary> summaries;
  // Each run's metrics.json is read once, for the aggregate, the batches and the comparison.
  std::vector<std::pair<std::string, eval::RunSet>> variant_runs;
  for (const auto& [label, sub] : variant_labels(scenarios)) {
    std::vector<fs::path> dirs;
    for (auto seed : finished) dirs.push_back(sub.empty() ? run_dir(out, seed) : run_dir(out, seed) / sub);
    const eval::RunSet& runs = variant_runs.emplace_back(label, eval::RunSet(dirs)).second;
    summaries.push_back(eval::aggregate_runs(label, runs));
    if (o.batch > 0 && dirs.size() >= static_cast<std::size_t>(o.batch)) {
      eval::BatchTest bt = eval::test_batches(label, runs, static_cast<std::size_t>(o.batch));
      for (auto& b : bt.batches)
        b.label = fmt::format("seeds {}-{}", finished[b.first], finished[b.first + b.size - 1]);
      summaries.back().batches = std::move(bt);
    } else if (o.batch > 0) {
      fmt::print(stderr, "{}: {} runs finished, fewer than one batch of {}: no batch test\n", label,
                 dirs.size(), o.batch);
    }
  }
  const eval::MonteCarloProvenance prov{o.scenario, file_fnv1a64(o.scenario), finished, failed};
  eval::write_monte_carlo(summaries, out, prov);
  // Every later variant against the first, seed by seed (the paper scenes: single against multi).
  std::vector<eval::PairedComparison> comparisons;
  for (std::size_t v = 1; v < variant_runs.size(); ++v)
    comparisons.push_back(eval::compare_paired(variant_runs[0].first, variant_runs[0].second,
                                               variant_runs[v].first, variant_runs[v].second));
  if (!comparisons.empty()) eval::write_paired(comparisons, out / "comparison.json");
  if (!o.no_plots) {
    fs::create_directories(out / "plots");
    eval::plot_monte_carlo_nees(summaries, out);
  }
  if (!o.quiet) {
    fmt::print("Monte Carlo of {}: {} runs finished (seeds {}..{}), {} failed\n", o.scenario,
               finished.size(), o.first_seed, o.first_seed + o.runs - 1, failed.size());
    fmt::print("{}", eval::format_monte_carlo(summaries));
    for (const auto& c : comparisons) fmt::print("{}", eval::format_paired(c));
    fmt::print("results: {}\n", out.string());
  }
  for (const auto& [seed, why] : failed) fmt::print(stderr, "failed: seed {}: {}\n", seed, why);
  return failed.empty() ? 0 : 1;
}

}  // namespace

Subcommand add_montecarlo(CLI::App& parent) {
  auto o = std::make_shared<MonteCarloOptions>();
  auto* cmd = parent.add_subcommand(
      "montecarlo",
      "Run N seeds of a scenario in parallel worker processes and aggregate them: average NEES "
      "with its 95% chi2 bounds, fraction of steps inside per phase, spread of Table 4");
  cmd->add_option("scenario", o->scenario, "Scenario YAML file")->required();
  cmd->add_option("--runs,-n", o->runs, "Number of runs (seeds first-seed .. first-seed+N-1)")->required();
  cmd->add_option("--jobs,-j", o->jobs, "Worker processes (default: one per core)");
  cmd->add_option("--out,-o", o->out, "Output directory (default: results/<scenario name>_montecarlo)");
  cmd->add_option("--first-seed", o->first_seed, "Seed of the first run (default 1)");
  add_variant_option(cmd, o->variants, "Run only this variant");
  add_step_limit(cmd, o->limit);
  cmd->add_option("--batch", o->batch,
                  "Also split the runs (by seed) into batches of this many and apply the per-step "
                  "bounds test to each, with how often an exactly consistent filter passes it");
  cmd->add_flag("--resume", o->resume, "Keep the runs already finished in --out and run the rest");
  cmd->add_flag("--no-plots", o->no_plots, "Skip the NEES plot (no gnuplot needed)");
  cmd->add_flag("--quiet,-q", o->quiet, "No progress line and no summary");
  return {cmd, [o] { return montecarlo_command(*o); }};
}

}  // namespace wingman::app
