// `wingman montecarlo --engine slurm`: the pending seeds as one Slurm array job, a task per seed
// running the same `wingman run` as a local worker (app/batch/slurm_script.hpp), followed until every
// task has ended; cmd_montecarlo.cpp then aggregates them as it does the local engine's. The
// output directory must be on a filesystem that the compute nodes share with this machine: the
// tasks write their results, logs and exit statuses there.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "app/batch/montecarlo_runs.hpp"
#include "app/batch/slurm_script.hpp"

namespace wingman::app {

struct SlurmStudy {
  RunSpec spec;                // its scenario an absolute path
  std::filesystem::path out;   // absolute
  std::string name;            // the scenario's name, for the job's
  bool quiet = false;
  // The study's frame cache is empty: its first seed runs alone, the others after it.
  bool fill_cache_first = false;
};

// A io::UsageError when sbatch or squeue is not on PATH.
void check_slurm_clients();
// Refuses, before anything is written, a directory that Slurm jobs were submitted into unless
// --resume is given, and with the local engine one whose jobs still have tasks queued or running
// (the same seeds would run twice).
void check_recorded_jobs(const std::filesystem::path& out, bool resume, bool slurm_engine);

// Follows the tasks of recorded jobs that still run seeds of `pending`, submits the other seeds as
// a new array job, and follows them all, adding each seed to `seeds` as its task ends (--detach:
// returns right after submitting). SIGINT/SIGTERM stop the following, never the job: what was left
// on the cluster and how to cancel or follow it is printed.
EngineEnd run_slurm(const SlurmStudy& study, const SlurmOptions& options,
                    const std::vector<std::uint64_t>& pending, SeedOutcomes& seeds);

}  // namespace wingman::app
