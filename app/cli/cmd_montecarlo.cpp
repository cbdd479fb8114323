// `wingman montecarlo`: N seeds of a scenario, each a `wingman run` writing its own results
// directory under <out>/runs/ (app/batch/montecarlo_runs.hpp), run by an engine: worker processes on
// this machine (--engine local, app/batch/local_engine.hpp) or a Slurm array job (--engine slurm,
// app/batch/slurm_engine.hpp). Both hand back the finished and the failed seeds, and one aggregation
// follows: docs/design.md, evaluation: average NEES with its chi^2 bounds per step, the fraction of
// steps inside them per phase, and the spread of Table 4 (eval/montecarlo), and every later
// variant compared with the first seed by seed (eval/paired: the paper scenes' single-UAV against
// multi-UAV). Ctrl-C or SIGTERM keeps the finished runs (exit 130/143); --resume skips them.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "app/cli/cli_options.hpp"
#include "io/interrupt.hpp"
#include "app/batch/local_engine.hpp"
#include "app/batch/montecarlo_runs.hpp"
#include "app/batch/montecarlo_study.hpp"
#include "app/batch/slurm_engine.hpp"
#include "app/cli/subcommand.hpp"
#include "app/config/variants.hpp"
#include "io/atomic_file.hpp"
#include "eval/stats/montecarlo.hpp"
#include "eval/stats/paired.hpp"
#include "eval/output/plots.hpp"
#include "io/results_dir.hpp"
#include "sim/scenario.hpp"

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
  std::string engine = "local";
  SlurmOptions slurm;
  FrameCacheCli frame_cache;
  bool no_frame_cache = false;
  std::vector<std::string> given;  // the options given on the command line, for the engine checks
};

bool given(const MonteCarloOptions& o, const std::string& option) {
  return std::find(o.given.begin(), o.given.end(), option) != o.given.end();
}

// Each engine takes its own options only; bad input fails here, before anything is written.
void check_engine(const MonteCarloOptions& o) {
  if (o.engine != "local" && o.engine != "slurm")
    throw io::UsageError(fmt::format("--engine {}: unknown engine; the engines are local (worker processes on "
                                 "this machine) and slurm (a Slurm array job)", o.engine));
  const bool slurm = o.engine == "slurm";
  if (slurm && given(o, "--jobs"))
    throw io::UsageError("--jobs is for --engine local; with --engine slurm the cluster decides how many runs go at "
                     "once (limit them with --array-limit)");
  for (const char* option : {"--partition", "--time", "--mem", "--array-limit", "--detach"})
    if (!slurm && given(o, option)) throw io::UsageError(fmt::format("{} is for --engine slurm", option));
  for (const auto& [option, value] : {std::pair{"--partition", &o.slurm.partition}, {"--time", &o.slurm.time},
                                      {"--mem", &o.slurm.mem}})
    if (std::any_of(value->begin(), value->end(), [](unsigned char c) { return c < 0x20; }))
      throw io::UsageError(fmt::format("{}: a control character in the value", option));
  if (slurm && given(o, "--array-limit") && o.slurm.array_limit < 1)
    throw io::UsageError(fmt::format("--array-limit {}: must be at least 1", o.slurm.array_limit));
  if (slurm) check_slurm_clients();
  if (o.no_frame_cache && (given(o, "--frame-cache") || given(o, "--frame-cache-size")))
    throw io::UsageError("--no-frame-cache with --frame-cache or --frame-cache-size: choose one");
  o.frame_cache.max_bytes();  // a bad size fails before the study opens
}

// Variant directories of one run: <run>/<variant> when the scenario has variants.
std::vector<std::pair<std::string, std::string>> variant_labels(const std::vector<RunConfig>& scns) {
  std::vector<std::pair<std::string, std::string>> v;  // label, subdirectory ("" = the run itself)
  const bool nested = scns.size() > 1 || !scns.front().variant.empty();
  for (const auto& s : scns) v.emplace_back(nested ? s.variant : s.name, nested ? s.variant : "");
  return v;
}

// The output directory: new, or one of ours (refused without --resume if it holds runs, and
// with other settings than its runs were made with). Splits the seeds into pending and finished.
void open_study(const MonteCarloOptions& o, const fs::path& out, const std::vector<RunConfig>& scenarios,
                std::vector<std::uint64_t>& pending, std::vector<std::uint64_t>& finished) {
  std::error_code ec;
  if (fs::exists(out)) {
    if (!fs::is_directory(out) || (!fs::exists(out / kMarker) && !fs::is_empty(out, ec)))
      throw io::UsageError(fmt::format("{}: exists and is not a wingman Monte Carlo directory; choose "
                                   "another --out", out.string()));
  }
  for (int i = 0; i < o.runs; ++i) {
    const std::uint64_t seed = o.first_seed + static_cast<std::uint64_t>(i);
    if (io::ResultsDir::is_results_dir(run_dir(out, seed))) {
      if (!o.resume)
        throw io::UsageError(fmt::format("{}: already holds finished runs (seed {}); pass --resume to "
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
  io::write_file_atomic(out / kMarker, o.scenario + "\n");
  // Staging directories of workers that were stopped: never complete; dropped once their process
  // is gone. The Slurm engine does it only when no task of its own may still be writing one.
  if (o.engine == "local")
    for (const auto& note : io::ResultsDir::remove_stale_staging(out / "runs"))
      if (!o.quiet) fmt::print(stderr, "note: {}\n", note);
}

// A run whose filter broke down and recorded it (estimator.on_numerical_failure: record) ends
// early: it is a failed seed, not one to aggregate.
void drop_numerical_failures(const fs::path& out, const std::vector<RunConfig>& scenarios, SeedOutcomes& seeds) {
  std::erase_if(seeds.finished, [&](std::uint64_t seed) {
    for (const auto& [label, sub] : variant_labels(scenarios)) {
      const std::string why = eval::recorded_numerical_failure(sub.empty() ? run_dir(out, seed) : run_dir(out, seed) / sub);
      if (why.empty()) continue;
      seeds.failed.emplace_back(seed, why);
      fmt::print(stderr, "run seed {} failed ({})\n", seed, why);
      return true;
    }
    return false;
  });
  std::sort(seeds.finished.begin(), seeds.finished.end());
}

// The one aggregation of both engines: montecarlo.json, nees.csv, comparison.json, the plot.
int aggregate(const MonteCarloOptions& o, const fs::path& out, const std::vector<RunConfig>& scenarios,
              SeedOutcomes seeds) {
  drop_numerical_failures(out, scenarios, seeds);
  const auto& finished = seeds.finished;
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
  const eval::MonteCarloProvenance prov{o.scenario, file_fnv1a64(o.scenario), finished, seeds.failed};
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
               finished.size(), o.first_seed, o.first_seed + o.runs - 1, seeds.failed.size());
    fmt::print("{}", eval::format_monte_carlo(summaries));
    for (const auto& c : comparisons) fmt::print("{}", eval::format_paired(c));
    fmt::print("results: {}\n", out.string());
  }
  for (const auto& [seed, why] : seeds.failed) fmt::print(stderr, "failed: seed {}: {}\n", seed, why);
  return seeds.failed.empty() ? 0 : 1;
}

// The study's frame cache: --frame-cache, else <out>/frame_cache, for rendered scenarios unless
// --no-frame-cache; absolute, for workers and cluster nodes that start elsewhere.
FrameCacheOptions frame_cache_of(const MonteCarloOptions& o, const fs::path& out, const std::vector<RunConfig>& scenarios) {
  const bool rendered = std::any_of(scenarios.begin(), scenarios.end(), [](const RunConfig& s) {
    return s.measurements == sim::MeasurementMode::Rendered;
  });
  if (o.no_frame_cache || !rendered) return {};
  FrameCacheCli cli = o.frame_cache;
  if (cli.dir.empty()) cli.dir = (fs::absolute(out) / "frame_cache").string();
  return cli.resolve();
}

bool cache_is_empty(const std::string& dir) {
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->path().extension() == ".frame") return false;
  return true;
}

// The pending seeds through the chosen engine; both leave the same finished and failed lists.
EngineEnd run_engine(const MonteCarloOptions& o, const fs::path& out, const std::vector<RunConfig>& scenarios,
                     const std::vector<std::uint64_t>& pending, SeedOutcomes& seeds) {
  RunSpec spec{o.scenario, o.variants, o.limit, frame_cache_of(o, out, scenarios)};
  if (o.engine == "slurm") {
    SlurmStudy study{spec, fs::absolute(out), scenarios.front().name, o.quiet,
                     !spec.frame_cache.dir.empty() && cache_is_empty(spec.frame_cache.dir)};
    study.spec.scenario = fs::absolute(o.scenario).string();  // the tasks may start elsewhere
    return run_slurm(study, o.slurm, pending, seeds);
  }
  const int jobs = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
  EngineEnd end = EngineEnd::done;
  std::size_t first = 0;
  if (!spec.frame_cache.dir.empty() && jobs > 1 && pending.size() > 1 && cache_is_empty(spec.frame_cache.dir)) {
    // An empty cache: the first run alone renders every frame once (the renderer takes every core)
    // rather than each of `jobs` workers rendering them side by side.
    end = run_local(spec, out, {pending.front()}, 1, o.quiet, seeds);
    first = 1;
  }
  if (end == EngineEnd::done)
    end = run_local(spec, out, {pending.begin() + static_cast<std::ptrdiff_t>(first), pending.end()}, jobs, o.quiet, seeds);
  if (end == EngineEnd::interrupted)
    fmt::print(stderr, "interrupted: {} of {} runs finished and kept in {}; rerun with --resume to "
               "run the rest\n", seeds.finished.size(), o.runs, out.string());
  return end;
}

int montecarlo_command(const MonteCarloOptions& o) {
  if (o.runs < 1) throw io::UsageError("--runs must be at least 1");
  if (o.batch != 0 && (o.batch < 2 || o.batch > o.runs))
    throw io::UsageError(fmt::format("--batch {}: a batch needs 2 to --runs ({}) runs", o.batch, o.runs));
  check_engine(o);
  // Bad input fails here, before any work.
  const auto scenarios = select_variants(load_run_configs(o.scenario), o.variants, o.scenario);
  o.limit.seconds(scenarios.front().rate);  // a bad --duration or --frames fails here, not per worker
  if (!o.no_plots && !eval::gnuplot_available())
    throw io::UsageError("gnuplot with the pngcairo terminal was not found; install it (setup.sh does) "
                     "or pass --no-plots");
  const fs::path out =
      o.out.empty() ? fs::path("results") / (scenarios.front().name + "_montecarlo") : fs::path(o.out);
  check_recorded_jobs(out, o.resume, o.engine == "slurm");

  std::vector<std::uint64_t> pending;
  SeedOutcomes seeds;
  open_study(o, out, scenarios, pending, seeds.finished);
  if (!o.quiet && !seeds.finished.empty())
    fmt::print(stderr, "resuming: {} of {} runs already finished\n", seeds.finished.size(), o.runs);
  switch (run_engine(o, out, scenarios, pending, seeds)) {
    case EngineEnd::detached: return 0;
    case EngineEnd::interrupted: return 128 + io::interrupt_signal();
    case EngineEnd::done: break;
  }
  return aggregate(o, out, scenarios, std::move(seeds));
}

}  // namespace

Subcommand add_montecarlo(CLI::App& parent) {
  auto o = std::make_shared<MonteCarloOptions>();
  auto* cmd = parent.add_subcommand(
      "montecarlo",
      "Run N seeds of a scenario in parallel worker processes, or as a Slurm array job, and aggregate "
      "them: average NEES with its 95% chi2 bounds, fraction of steps inside per phase, spread of Table 4");
  cmd->add_option("scenario", o->scenario, "Scenario YAML file")->required();
  cmd->add_option("--runs,-n", o->runs, "Number of runs (seeds first-seed .. first-seed+N-1)")->required();
  cmd->add_option("--jobs,-j", o->jobs, "Local engine: worker processes (default: one per core)");
  cmd->add_option("--out,-o", o->out, "Output directory (default: results/<scenario name>_montecarlo)");
  cmd->add_option("--first-seed", o->first_seed, "Seed of the first run (default 1)");
  add_variant_option(cmd, o->variants, "Run only this variant");
  add_step_limit(cmd, o->limit);
  cmd->add_option("--batch", o->batch,
                  "Also split the runs (by seed) into batches of this many and apply the per-step "
                  "bounds test to each, with how often an exactly consistent filter passes it");
  cmd->add_flag("--resume", o->resume,
                "Keep the runs already finished in --out and run the rest (Slurm: follow the tasks still "
                "queued or running, and submit the seeds neither finished nor queued)");
  cmd->add_flag("--no-plots", o->no_plots, "Skip the NEES plot (no gnuplot needed)");
  cmd->add_flag("--quiet,-q", o->quiet, "No progress line and no summary");
  add_frame_cache_options(cmd, o->frame_cache, "By default <out>/frame_cache for rendered scenarios.");
  cmd->add_flag("--no-frame-cache", o->no_frame_cache, "Render every run's frames (no frame cache)");
  cmd->add_option("--engine", o->engine,
                  "Where the runs go: local (worker processes on this machine, the default) or slurm (one "
                  "Slurm array job, a task per seed; --out must be on a filesystem the compute nodes share)");
  cmd->add_option("--partition", o->slurm.partition, "Slurm: the partition (sbatch --partition)");
  cmd->add_option("--time", o->slurm.time, "Slurm: each task's time limit (sbatch --time, e.g. 30 or 1:00:00)");
  cmd->add_option("--mem", o->slurm.mem, "Slurm: each task's memory (sbatch --mem, e.g. 2G)");
  cmd->add_option("--array-limit", o->slurm.array_limit, "Slurm: at most this many tasks at once (--array=...%K)");
  cmd->add_flag("--detach", o->slurm.detach,
                "Slurm: submit and return; the same command with --resume later follows the job and aggregates");
  return {cmd, [o, cmd] {
            for (const CLI::Option* opt : cmd->get_options())
              if (opt->count() > 0) o->given.push_back(opt->get_name());
            return montecarlo_command(*o);
          }};
}

}  // namespace wingman::app
