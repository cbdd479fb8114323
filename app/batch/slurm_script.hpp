// The files of `wingman montecarlo --engine slurm` in the output directory, and the sbatch array
// script of one submission (docs/design.md, Monte Carlo directory):
//   slurm/array-<k>.sbatch    submission k's script; Slurm keeps its own copy of what it was sent
//   slurm/seeds-<k>.txt       its seeds, one a line: array task i runs the seed on line i+1
//   slurm/jobs                "<job id> seeds-<k>.txt", a line per submission that Slurm took
//   slurm/logs/<job>_<i>.out  what Slurm itself says about task i (a time limit, say); the run's
//                             own output goes to runs/seed<S>.log as with the local engine
//   slurm/status/seed<S>      "<exit code> <job>_<i>": written whole (tmp + mv) by the task once
//                             its `wingman run` has ended, so a follower tells done from failed
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "app/batch/montecarlo_runs.hpp"

namespace wingman::app {

struct SlurmOptions {
  std::string partition, time, mem;  // passed to sbatch as they are; "" = the cluster's default
  int array_limit = 0;               // tasks running at once (--array=...%K); 0 = no limit
  bool detach = false;               // submit and return
};

// One submission: the seeds of an array job and what its tasks need to run them.
struct ArrayJob {
  std::filesystem::path out;         // the study's directory, absolute
  int index = 1;                     // k of array-<k>.sbatch and seeds-<k>.txt
  std::vector<std::uint64_t> seeds;  // task i runs seeds[i]
  std::string name;                  // Slurm's job name
  std::filesystem::path wingman;     // the binary the tasks run, absolute
  std::filesystem::path cwd;         // the tasks' working directory: the submitter's
  std::string after;                 // a job id: start once it has ended (--dependency=afterany)
};

std::filesystem::path slurm_dir(const std::filesystem::path& out);
std::filesystem::path script_path(const std::filesystem::path& out, int index);
std::filesystem::path seeds_path(const std::filesystem::path& out, int index);
std::filesystem::path status_path(const std::filesystem::path& out, std::uint64_t seed);
std::filesystem::path task_log(const std::filesystem::path& out, const std::string& job, int task);

// `s` in single quotes for bash.
std::string shell_quote(const std::string& s);
// The script's text: #SBATCH lines from `options`, then the task's `wingman run` (run_arguments
// with the seed filled in by the shell) and its status file. `spec.scenario` must be absolute.
std::string array_script(const ArrayJob& job, const RunSpec& spec, const SlurmOptions& options);

}  // namespace wingman::app
