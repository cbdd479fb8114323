// What `wingman montecarlo --engine slurm` asks of Slurm and of its own files (app/batch/slurm_script.hpp):
// submitting an array job, the live tasks of a job (squeue), the jobs recorded in the output
// directory, and the exit statuses the tasks wrote.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace wingman::app {

// Submits `script` with `sbatch --parsable`; returns the job id. A refusal (sbatch's exit status
// not 0) is a io::UsageError showing what sbatch said.
std::string submit_array(const std::filesystem::path& script);

// The live tasks of an array job: task index -> squeue's state code (PD, R, CG, ...). A job that
// Slurm no longer knows has none. nullopt when squeue failed (the controller did not answer, say),
// with its message in `error`.
std::optional<std::map<int, std::string>> live_tasks(const std::string& job, std::string& error);
// squeue -h -r -o '%i %t' output, the lines of `job` only.
std::map<int, std::string> parse_squeue(const std::string& text, const std::string& job);

struct RecordedJob {
  std::string id;
  std::vector<std::uint64_t> seeds;  // task i ran seeds[i]
};
// slurm/jobs with each job's seeds; a missing file is no job. Throws io::UsageError for a damaged one.
std::vector<RecordedJob> read_jobs(const std::filesystem::path& out);
// Appends a submission to slurm/jobs (rewritten atomically).
void record_job(const std::filesystem::path& out, const std::string& id, int index);

struct TaskStatus {
  int exit_code = 0;
  std::string task;  // "<job>_<i>": the task that wrote it
};
// slurm/status/seed<S> of every seed that has one (one listing of the directory a poll).
std::map<std::uint64_t, TaskStatus> read_statuses(const std::filesystem::path& out);

}  // namespace wingman::app
