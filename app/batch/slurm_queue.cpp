#include "app/batch/slurm_queue.hpp"

#include <fmt/core.h>

#include <charconv>
#include <fstream>
#include <sstream>

#include "app/batch/slurm_script.hpp"
#include "io/usage_error.hpp"
#include "app/batch/subprocess.hpp"
#include "io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace wingman::app {
namespace {

std::string trimmed(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

template <typename T>
std::optional<T> number(const std::string& s) {
  T v{};
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

std::vector<std::uint64_t> read_seeds(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw io::UsageError(fmt::format("{}: missing; it lists the seeds of a recorded Slurm job", file.string()));
  std::vector<std::uint64_t> seeds;
  for (std::string line; std::getline(in, line);) {
    if (trimmed(line).empty()) continue;
    const auto seed = number<std::uint64_t>(trimmed(line));
    if (!seed) throw io::UsageError(fmt::format("{}: '{}' is not a seed", file.string(), line));
    seeds.push_back(*seed);
  }
  return seeds;
}

}  // namespace

std::string submit_array(const fs::path& script) {
  const ProcessOutput r = run_process({"sbatch", "--parsable", script.string()});
  const std::string said = trimmed(r.err.empty() ? r.out : r.err);
  if (r.exit_code != 0)
    throw io::UsageError(fmt::format("sbatch refused the job (exit {}): {}; nothing was submitted", r.exit_code,
                                 said.empty() ? "(no message)" : said));
  const std::string id = trimmed(r.out.substr(0, r.out.find(';')));  // "<id>;<cluster>" on multi-cluster setups
  if (!number<std::uint64_t>(id))
    throw std::runtime_error(fmt::format("sbatch --parsable printed '{}', not a job id", trimmed(r.out)));
  return id;
}

std::map<int, std::string> parse_squeue(const std::string& text, const std::string& job) {
  std::map<int, std::string> tasks;
  std::istringstream in(text);
  for (std::string id, state; in >> id >> state;) {
    const auto us = id.find('_');
    if (us == std::string::npos || id.substr(0, us) != job) continue;
    if (const auto task = number<int>(id.substr(us + 1))) tasks[*task] = state;
  }
  return tasks;
}

std::optional<std::map<int, std::string>> live_tasks(const std::string& job, std::string& error) {
  const ProcessOutput r = run_process({"squeue", "-h", "-r", "-j", job, "-o", "%i %t"});
  if (r.exit_code == 0) return parse_squeue(r.out, job);
  // Slurm forgets an ended job after MinJobAge (300 s by default).
  if (r.err.find("Invalid job id") != std::string::npos) return std::map<int, std::string>{};
  error = trimmed(r.err.empty() ? r.out : r.err);
  return std::nullopt;
}

std::vector<RecordedJob> read_jobs(const fs::path& out) {
  const fs::path file = slurm_dir(out) / "jobs";
  std::ifstream in(file);
  std::vector<RecordedJob> jobs;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string id, seeds;
    if (!(words >> id)) continue;
    if (!(words >> seeds) || !number<std::uint64_t>(id) || seeds.find('/') != std::string::npos)
      throw io::UsageError(fmt::format("{}: line '{}' is not '<job id> seeds-<k>.txt'", file.string(), line));
    jobs.push_back({id, read_seeds(slurm_dir(out) / seeds)});
  }
  return jobs;
}

void record_job(const fs::path& out, const std::string& id, int index) {
  const fs::path file = slurm_dir(out) / "jobs";
  std::string text;
  if (std::ifstream in(file); in) {
    std::stringstream s;
    s << in.rdbuf();
    text = s.str();
  }
  if (!text.empty() && text.back() != '\n') text += '\n';
  text += fmt::format("{} {}\n", id, seeds_path(out, index).filename().string());
  io::write_file_atomic(file, text);
}

std::map<std::uint64_t, TaskStatus> read_statuses(const fs::path& out) {
  std::map<std::uint64_t, TaskStatus> statuses;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(slurm_dir(out) / "status", ec)) {
    const std::string name = entry.path().filename().string();
    const auto seed = name.rfind("seed", 0) == 0 ? number<std::uint64_t>(name.substr(4)) : std::nullopt;
    if (!seed) continue;  // a task's temporary file
    std::ifstream in(entry.path());
    std::string code, task;
    if (!(in >> code >> task) || !number<int>(code)) continue;
    statuses[*seed] = {*number<int>(code), task};
  }
  return statuses;
}

}  // namespace wingman::app
