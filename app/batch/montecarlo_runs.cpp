#include "app/batch/montecarlo_runs.hpp"

#include <fmt/core.h>

#include <fstream>

namespace fs = std::filesystem;

namespace wingman::app {

std::vector<std::string> run_arguments(const RunSpec& spec, const std::string& seed, const fs::path& out) {
  std::vector<std::string> args = {"run",  spec.scenario, "--seed", seed, "--out", run_dir(out, seed).string(),
                                   "--no-plots", "-q"};
  for (const auto& v : spec.variants) args.insert(args.end(), {"--variant", v});
  if (spec.limit.duration) args.insert(args.end(), {"--duration", fmt::format("{}", *spec.limit.duration)});
  if (spec.limit.frames) args.insert(args.end(), {"--frames", std::to_string(*spec.limit.frames)});
  if (!spec.frame_cache.dir.empty())
    args.insert(args.end(), {"--frame-cache", spec.frame_cache.dir, "--frame-cache-size",
                             std::to_string(spec.frame_cache.max_bytes)});
  return args;
}

fs::path run_dir(const fs::path& out, const std::string& seed) { return out / "runs" / ("seed" + seed); }
fs::path run_dir(const fs::path& out, std::uint64_t seed) { return run_dir(out, std::to_string(seed)); }
fs::path run_log(const fs::path& out, const std::string& seed) { return out / "runs" / ("seed" + seed + ".log"); }
fs::path run_log(const fs::path& out, std::uint64_t seed) { return run_log(out, std::to_string(seed)); }

std::string last_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last.empty() ? "(no output)" : last;
}

}  // namespace wingman::app
