// What the Monte Carlo engines share (app/batch/local_engine.hpp, app/batch/slurm_engine.hpp): the one
// `wingman run` command line of a seed, where a seed's results and log go, and the seeds an
// engine hands back to the one aggregation of cmd_montecarlo.cpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "app/config/step_limit.hpp"
#include "app/pipeline/frame_producer.hpp"

namespace wingman::app {

// The options a run of the study is made with.
struct RunSpec {
  std::string scenario;
  std::vector<std::string> variants;
  StepLimit limit;
  FrameCacheOptions frame_cache;  // one directory every run of the study shares
};

// `wingman run`'s arguments (after argv[0]) for one seed, written into run_dir(out, seed). Both
// engines build their command lines here, so an option added to it reaches every engine. `seed`
// is text so that the Slurm engine can pass a placeholder that its script fills in.
std::vector<std::string> run_arguments(const RunSpec& spec, const std::string& seed,
                                       const std::filesystem::path& out);
// <out>/runs/seed<S>: the seed's results directory; <out>/runs/seed<S>.log: its output.
std::filesystem::path run_dir(const std::filesystem::path& out, const std::string& seed);
std::filesystem::path run_dir(const std::filesystem::path& out, std::uint64_t seed);
std::filesystem::path run_log(const std::filesystem::path& out, const std::string& seed);
std::filesystem::path run_log(const std::filesystem::path& out, std::uint64_t seed);
// The last non-empty line of a log (a failed run's error message), or "(no output)".
std::string last_line(const std::filesystem::path& log);

// The seeds of a study as the engines leave them: finished (a results directory) or failed (why).
struct SeedOutcomes {
  std::vector<std::uint64_t> finished;
  std::vector<std::pair<std::uint64_t, std::string>> failed;
};

// How an engine's turn ended: every pending seed finished or failed; submitted and left to the
// cluster (--detach); or stopped by SIGINT/SIGTERM (the engine has said what it left behind).
enum class EngineEnd { done, detached, interrupted };

}  // namespace wingman::app
