#include "app/batch/slurm_script.hpp"

#include <fmt/core.h>

namespace fs = std::filesystem;

namespace wingman::app {
namespace {

// Stands for the seed in run_arguments' output; the script puts "$seed" there. Never in a path.
constexpr const char* kSeedToken = "\x1fseed\x1f";

// An argument for bash: quoted, with every seed placeholder replaced by "$seed".
std::string shell_word(const std::string& arg) {
  std::string word;
  std::size_t from = 0;
  for (std::size_t at; (at = arg.find(kSeedToken, from)) != std::string::npos;) {
    if (at > from) word += shell_quote(arg.substr(from, at - from));
    word += "\"$seed\"";
    from = at + std::string(kSeedToken).size();
  }
  if (from < arg.size() || word.empty()) word += shell_quote(arg.substr(from));
  return word;
}

std::string sbatch_lines(const ArrayJob& job, const SlurmOptions& o) {
  std::string s = fmt::format("#SBATCH --job-name={}\n", job.name);
  s += fmt::format("#SBATCH --array=0-{}{}\n", job.seeds.size() - 1,
                   o.array_limit > 0 ? fmt::format("%{}", o.array_limit) : "");
  s += fmt::format("#SBATCH --ntasks=1\n#SBATCH --output={}\n", (slurm_dir(job.out) / "logs" / "%A_%a.out").string());
  s += fmt::format("#SBATCH --chdir={}\n", job.cwd.string());
  if (!o.partition.empty()) s += fmt::format("#SBATCH --partition={}\n", o.partition);
  if (!o.time.empty()) s += fmt::format("#SBATCH --time={}\n", o.time);
  if (!o.mem.empty()) s += fmt::format("#SBATCH --mem={}\n", o.mem);
  if (!job.after.empty()) s += fmt::format("#SBATCH --dependency=afterany:{}\n", job.after);
  return s;
}

}  // namespace

fs::path slurm_dir(const fs::path& out) { return out / "slurm"; }
fs::path script_path(const fs::path& out, int index) {
  return slurm_dir(out) / fmt::format("array-{}.sbatch", index);
}
fs::path seeds_path(const fs::path& out, int index) { return slurm_dir(out) / fmt::format("seeds-{}.txt", index); }
fs::path status_path(const fs::path& out, std::uint64_t seed) {
  return slurm_dir(out) / "status" / fmt::format("seed{}", seed);
}
fs::path task_log(const fs::path& out, const std::string& job, int task) {
  return slurm_dir(out) / "logs" / fmt::format("{}_{}.out", job, task);
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string array_script(const ArrayJob& job, const RunSpec& spec, const SlurmOptions& options) {
  std::string run = shell_quote(job.wingman.string());
  for (const auto& a : run_arguments(spec, kSeedToken, job.out)) {
    run += ' ';  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on " " + s
    run += shell_word(a);
  }
  const std::string status = shell_word((slurm_dir(job.out) / "status" / "seed").string() + kSeedToken);
  std::string s = "#!/bin/bash\n";
  s += fmt::format("# wingman montecarlo --engine slurm, submission {}: array task i runs the seed on line i+1\n"
                   "# of {}, logs into runs/seed<S>.log and records its exit status in slurm/status/seed<S>.\n",
                   job.index, seeds_path(job.out, job.index).filename().string());
  s += sbatch_lines(job, options);
  s += "set -u\n";
  s += "unset WINGMAN_WORKER_OF  # a cluster task, not a local worker: no parent process to stop with\n";
  s += fmt::format("seed=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" {})\n",
                   shell_quote(seeds_path(job.out, job.index).string()));
  s += "if [ -z \"$seed\" ]; then echo \"no seed for array task $SLURM_ARRAY_TASK_ID\" >&2; exit 2; fi\n";
  s += fmt::format("{} > {} 2>&1\n", run, shell_word(run_log(job.out, kSeedToken).string()));
  s += "rc=$?\n";
  s += fmt::format("status={}\n", status);
  s += "# Whole or absent: the follower reads it as soon as it appears.\n";
  s += "echo \"$rc ${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\" > \"$status.tmp.$SLURM_JOB_ID\" &&\n"
       "  mv -f \"$status.tmp.$SLURM_JOB_ID\" \"$status\"\n";
  s += "exit \"$rc\"\n";
  return s;
}

}  // namespace wingman::app
